// Two rollers on a block (plane strain): the lower half discs of radius R = 1 centred at
// (-2, R) and (2, R), touching the block [-6, 6] x [-6, 0] at (-2, 0) and (2, 0); elements
// of a/10 within 1.5 a of the two contacts (a = 0.06: two_rollers.toml's half-width),
// growing by 5 % of the distance away. The bodies share no node (AutoCoherence off: each
// has its own point at a contact).
Geometry.AutoCoherence = 0;
R = 1; L = 6; a = 0.06; h = a / 10;
// the block, its top split at the contacts (points 2 and 3)
Point(1) = {-L, 0, 0}; Point(2) = {-2, 0, 0}; Point(3) = {2, 0, 0}; Point(4) = {L, 0, 0};
Point(5) = {L, -L, 0}; Point(6) = {-L, -L, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 6};
Line(6) = {6, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6};
Plane Surface(1) = {1};
// the rollers: each a lower half disc, its lowest point apart from the block's
For k In {0:1}
  c = -2 + 4 * k;
  p = 10 + 10 * k;
  Point(p) = {c, 0, 0}; Point(p + 1) = {c + R, R, 0}; Point(p + 2) = {c, R, 0};
  Point(p + 3) = {c - R, R, 0};
  Circle(p) = {p + 3, p + 2, p}; Circle(p + 1) = {p, p + 2, p + 1};
  Line(p + 2) = {p + 1, p + 3};
  Curve Loop(p) = {p, p + 1, p + 2};
  Plane Surface(p) = {p};
EndFor
Physical Surface("block") = {1};
Physical Surface("rollers") = {10, 20};
Physical Curve("block_top") = {1, 2, 3};
Physical Curve("block_bottom") = {5};
Physical Curve("left_surface") = {10, 11};
Physical Curve("right_surface") = {20, 21};
Physical Curve("equators") = {12, 22};
Field[1] = Distance;
Field[1].PointsList = {2, 3, 10, 20};
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
