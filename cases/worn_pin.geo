// A flat pin [-w/2, w/2] x [0, w] (w = 1) on a flat [-L, L] x [-L, 0] (L = 4), plane
// strain: elements of h = 0.02 along the pin's face and under it (within 0.05 of the
// face), growing by 20 % of the distance away. The bodies share no node (AutoCoherence
// off: the pin's face and the flat's top are two curves).
Geometry.AutoCoherence = 0;
w = 1; L = 4; h = 0.02;
Point(1) = {-w / 2, 0, 0}; Point(2) = {w / 2, 0, 0}; Point(3) = {w / 2, w, 0};
Point(4) = {-w / 2, w, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Point(11) = {-L, -L, 0}; Point(12) = {L, -L, 0}; Point(13) = {L, 0, 0};
Point(14) = {-L, 0, 0};
Line(11) = {11, 12}; Line(12) = {12, 13}; Line(13) = {13, 14}; Line(14) = {14, 11};
Curve Loop(11) = {11, 12, 13, 14};
Plane Surface(11) = {11};
Physical Surface("pin") = {1};
Physical Surface("flat") = {11};
Physical Curve("pin_face") = {1};
Physical Curve("pin_top") = {3};
Physical Curve("pin_sides") = {2, 4};
Physical Curve("flat_top") = {13};
Physical Curve("flat_bottom") = {11};
Physical Curve("flat_sides") = {12, 14};
Field[1] = Distance;
Field[1].CurvesList = {1};
Field[1].Sampling = 200;
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h;
Field[2].SizeMax = h + 0.2 * L;
Field[2].DistMin = 0.05;
Field[2].DistMax = L;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
