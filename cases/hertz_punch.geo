// The block under the punch of demos/punch.py (axisymmetric, x = r, y = z): 1000 contact
// radii wide and deep, elements of a/20 within 1.5 a of the axis growing by 5 % of the
// distance away from it (a = sqrt(R delta) = 0.1 for R = 1, delta = 0.01).
a = 0.1; L = 1000 * a; h = a / 20;
Point(1) = {0, 0, 0}; Point(2) = {L, 0, 0}; Point(3) = {L, -L, 0}; Point(4) = {0, -L, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("contact") = {1};
Physical Curve("side") = {2};
Physical Curve("bottom") = {3};
Physical Curve("symmetry_x") = {4};
Physical Surface("block") = {1};
Field[1] = Distance;
Field[1].PointsList = {1};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h;
Field[2].SizeMax = h + 0.05 * L;
Field[2].DistMin = 1.5 * a;
Field[2].DistMax = L;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
