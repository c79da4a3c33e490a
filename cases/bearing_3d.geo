// A slice of the shaft in its bearing (demos/bearing.py) in 3D: a steel shaft of radius
// R1 = 10 around a hub of radius 2, in a bronze housing of bore R1 + c (c = 0.1) and
// outer radius 20, both Lz = 1 long (z from 0 to Lz). Elements of `fine` along the lower
// halves of the shaft's surface and the bore (where the contact arc grows), growing away.
SetFactory("OpenCASCADE");
R1 = 10; c = 0.1; R3 = 20; hub = 2; Lz = 1; fine = 0.3; e = 1e-3;
Cylinder(1) = {0, 0, 0, 0, 0, Lz, R1};
Cylinder(2) = {0, 0, 0, 0, 0, Lz, hub};
BooleanDifference(3) = {Volume{1}; Delete;}{Volume{2}; Delete;};
Cylinder(4) = {0, 0, 0, 0, 0, Lz, R3};
Cylinder(5) = {0, 0, 0, 0, 0, Lz, R1 + c};
BooleanDifference(6) = {Volume{4}; Delete;}{Volume{5}; Delete;};
ends() = Surface In BoundingBox{-R3 - e, -R3 - e, -e, R3 + e, R3 + e, e};
ends() += Surface In BoundingBox{-R3 - e, -R3 - e, Lz - e, R3 + e, R3 + e, Lz + e};
hub() = Surface In BoundingBox{-hub - e, -hub - e, -e, hub + e, hub + e, Lz + e};
shaft() = Surface In BoundingBox{-R1 - e, -R1 - e, -e, R1 + e, R1 + e, Lz + e};
shaft() -= ends();
shaft() -= hub();
bore() = Surface In BoundingBox{-R1 - c - e, -R1 - c - e, -e, R1 + c + e, R1 + c + e, Lz + e};
bore() -= ends();
bore() -= hub();
bore() -= shaft();
outer() = Surface In BoundingBox{-R3 - e, -R3 - e, -e, R3 + e, R3 + e, Lz + e};
outer() -= ends();
outer() -= hub();
outer() -= shaft();
outer() -= bore();
Physical Volume("shaft") = {3};
Physical Volume("housing") = {6};
Physical Surface("shaft_surface") = {shaft()};
Physical Surface("bore") = {bore()};
Physical Surface("hub") = {hub()};
Physical Surface("housing_outer") = {outer()};
Physical Surface("ends") = {ends()};
Field[1] = MathEval;
Field[1].F = Sprintf("%g + 0.25 * Max(y + 0.5 * %g, 0) + 0.1 * Abs(Sqrt(x * x + y * y) - %g)", fine, R1, R1);
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
