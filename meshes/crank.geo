// A crank (connecting lever) for femb: a big boss with a bore at the origin, a small boss with
// a bore at x = 150 mm, joined by a web; steel, dimensions in metres (part units SI).
// Physical surfaces name the interfaces: the two bore surfaces. The mesh size comes from the
// part file (mesh.size -> Mesh.MeshSizeMax).
SetFactory("OpenCASCADE");
t = 0.020;                       // boss thickness (z from 0 to t)
Cylinder(1) = {0, 0, 0, 0, 0, t, 0.030};
Cylinder(2) = {0.150, 0, 0, 0, 0, t, 0.018};
Box(3) = {0, -0.012, 0.004, 0.150, 0.024, 0.012};   // web 24 x 12 mm
Cylinder(4) = {0, 0, -0.001, 0, 0, t + 0.002, 0.015};     // big bore, radius 15 mm
Cylinder(5) = {0.150, 0, -0.001, 0, 0, t + 0.002, 0.008}; // small bore, radius 8 mm
BooleanUnion(6) = { Volume{1}; Delete; }{ Volume{2, 3}; Delete; };
BooleanDifference(7) = { Volume{6}; Delete; }{ Volume{4, 5}; Delete; };
e = 1e-4;
big() = Surface In BoundingBox{-0.015 - e, -0.015 - e, -e, 0.015 + e, 0.015 + e, t + e};
small() = Surface In BoundingBox{0.150 - 0.008 - e, -0.008 - e, -e, 0.150 + 0.008 + e, 0.008 + e, t + e};
Physical Surface("big_bore") = big();
Physical Surface("small_bore") = small();
Physical Volume("crank") = {7};
