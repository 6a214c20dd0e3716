// The crank of crank.geo read from a STEP file (crank.step, written by gmsh/OpenCASCADE from
// crank.geo): a STEP file carries no named surfaces, so this wrapper merges it and names the
// interface surfaces (the bores) as physical groups for femb.
SetFactory("OpenCASCADE");
Merge "crank.step";
t = 0.020;
e = 1e-4;
big() = Surface In BoundingBox{-0.015 - e, -0.015 - e, -e, 0.015 + e, 0.015 + e, t + e};
small() = Surface In BoundingBox{0.150 - 0.008 - e, -0.008 - e, -e, 0.150 + 0.008 + e, 0.008 + e, t + e};
Physical Surface("big_bore") = big();
Physical Surface("small_bore") = small();
Physical Volume("crank") = Volume{:};
