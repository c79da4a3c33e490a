// The bracket of demos/bracket.py as a .geo (OpenCASCADE), lengths in mm: a base plate
// 100 x 60 x 10 with two bolt holes (diameter 12) at x = 70, an arm 10 x 60 x 80 with a
// loaded hole (diameter 16) at z = 60, an 8 mm fillet between them. Used by bracket.toml.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 100, 60, 10};
Box(2) = {0, 0, 0, 10, 60, 80};
body() = BooleanUnion{ Volume{1}; Delete; }{ Volume{2}; Delete; };
inner() = Curve In BoundingBox{9.9, -0.1, 9.9, 10.1, 60.1, 10.1};
body() = Fillet{body(0)}{inner()}{8};
Cylinder(10) = {70, 15, -1, 0, 0, 12, 6};
Cylinder(11) = {70, 45, -1, 0, 0, 12, 6};
Cylinder(12) = {-1, 30, 60, 12, 0, 0, 8};
part() = BooleanDifference{ Volume{body(0)}; Delete; }{ Volume{10, 11, 12}; Delete; };
Physical Surface("bolts") = Surface In BoundingBox{63.9, 8.9, -0.1, 76.1, 51.1, 10.1};
Physical Surface("load") = Surface In BoundingBox{-0.1, 21.9, 51.9, 10.1, 38.1, 68.1};
Physical Surface("base") = Surface In BoundingBox{-0.1, -0.1, -0.1, 100.1, 60.1, 0.1};
Physical Volume("solid") = {part()};
// as the scene meshes it: curvature-driven sizes on the holes and the fillet
Mesh.MeshSizeFromCurvature = 12;
Mesh.MeshSizeMax = 6;
Mesh.MeshSizeMin = 1.5;
Mesh.ElementOrder = 2;  // curved edges: the holes keep their area (the traction is per area)
