// An incompressible hollow sphere (inner radius 1, outer 1.2), axisymmetric: a quarter of
// its meridian section, x = r, y = z. Used by inflated_sphere.toml.
A = 1; B = 1.2; h = 0.1;
Mesh.ElementOrder = 2;  // curved (quadratic) edges follow the circles
Point(1) = {0, 0, 0, h};
Point(2) = {A, 0, 0, h};
Point(3) = {B, 0, 0, h};
Point(4) = {0, B, 0, h};
Point(5) = {0, A, 0, h};
Line(1) = {2, 3};
Circle(2) = {3, 1, 4};
Line(3) = {4, 5};
Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("equator") = {1};  // z = 0: u_z = 0 (symmetry)
Physical Curve("outer") = {2};
Physical Curve("axis") = {3};     // r = 0: u_r = 0
Physical Curve("inner") = {4};
Physical Surface("wall") = {1};
