// A thick cylinder under internal pressure: a quarter of the annulus a < r < b
// (plane strain). Lengths in mm. Used by thick_cylinder.toml.
a = 10; b = 20; h = 1.5;
Mesh.ElementOrder = 2;  // curved (quadratic) edges follow the circles
Point(1) = {0, 0, 0, h};
Point(2) = {a, 0, 0, h};
Point(3) = {b, 0, 0, h};
Point(4) = {0, b, 0, h};
Point(5) = {0, a, 0, h};
Line(1) = {2, 3};
Circle(2) = {3, 1, 4};
Line(3) = {4, 5};
Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("symmetry_y") = {1};  // on y = 0: u_y = 0
Physical Curve("outer") = {2};
Physical Curve("symmetry_x") = {3};  // on x = 0: u_x = 0
Physical Curve("inner") = {4};
Physical Surface("body") = {1};
