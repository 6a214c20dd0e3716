// One 1 m segment of the thesis's cantilever plate (8.4: 10 m x 1 m x 0.1 m): x along the plate,
// y across (0..1), z through the thickness (-0.05..0.05). Each end face is cut into two patches,
// y in [0, 0.45] and [0.55, 1], that tie the segment to its neighbours (interfaces at the
// corners); the 0.1 m strip between them stays free, because two interfaces must not share
// nodes. The mesh size comes from the part file (mesh.size -> Mesh.MeshSizeMax).
SetFactory("OpenCASCADE");
Box(1) = {0, 0, -0.05, 1, 0.45, 0.1};
Box(2) = {0, 0.45, -0.05, 1, 0.1, 0.1};
Box(3) = {0, 0.55, -0.05, 1, 0.45, 0.1};
BooleanFragments{ Volume{1, 2, 3}; Delete; }{}
e = 1e-6;
Physical Surface("xmin_1") = Surface In BoundingBox{-e, -e, -0.05 - e, e, 0.45 + e, 0.05 + e};
Physical Surface("xmin_2") = Surface In BoundingBox{-e, 0.55 - e, -0.05 - e, e, 1 + e, 0.05 + e};
Physical Surface("xmax_1") = Surface In BoundingBox{1 - e, -e, -0.05 - e, 1 + e, 0.45 + e, 0.05 + e};
Physical Surface("xmax_2") = Surface In BoundingBox{1 - e, 0.55 - e, -0.05 - e, 1 + e, 1 + e, 0.05 + e};
Physical Volume("plate") = {1, 2, 3};
