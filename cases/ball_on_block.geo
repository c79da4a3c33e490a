// A ball on a block (axisymmetric, x = r, y = z): the ball's lower quarter disc (R = 1)
// touching the block (4 x 4) at the origin, elements of a/20 within 1.5 a of the contact
// growing by 5 % of the distance away from it (a = 0.1: the contact radius of
// ball_on_block.toml). The two bodies are apart: each has its own point at the origin
// (AutoCoherence off, so gmsh does not merge them into one node).
Geometry.AutoCoherence = 0;
R = 1; L = 4; a = 0.1; h = a / 20;
s = 0.3; z = R - Sqrt(R * R - s * s);  // where the ball's contact curve ends (r = 0.3)
// the block
Point(1) = {0, 0, 0}; Point(2) = {s, 0, 0}; Point(3) = {L, 0, 0};
Point(4) = {L, -L, 0}; Point(5) = {0, -L, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 1};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
// the ball
Point(6) = {0, 0, 0}; Point(7) = {s, z, 0}; Point(8) = {R, R, 0}; Point(9) = {0, R, 0};
Circle(6) = {6, 9, 7}; Circle(7) = {7, 9, 8}; Line(8) = {8, 9}; Line(9) = {9, 6};
Curve Loop(2) = {6, 7, 8, 9};
Plane Surface(2) = {2};
Physical Surface("block") = {1};
Physical Surface("ball") = {2};
Physical Curve("block_top") = {1};
Physical Curve("block_bottom") = {4};
Physical Curve("block_axis") = {5};
Physical Curve("ball_surface") = {6};
Physical Curve("ball_equator") = {8};
Physical Curve("ball_axis") = {9};
Field[1] = Distance;
Field[1].PointsList = {1, 6};
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
