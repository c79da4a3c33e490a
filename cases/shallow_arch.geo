// A shallow circular arch: span 1000 mm, rise 30 mm, thickness 10 mm, clamped at both
// ends (plane stress). Lengths in mm. Used by shallow_arch.toml.
c = 500; f = 30; t = 10; h = 5;
R = (c * c + f * f) / (2 * f);  // radius of the inner face through (±c, 0) and (0, f)
yc = f - R;                      // the centre
yt = yc + Sqrt((R + t) * (R + t) - c * c);  // the outer face at x = ±c
Point(1) = {0, yc, 0, h};
Point(2) = {-c, 0, 0, h};
Point(3) = {c, 0, 0, h};
Point(4) = {c, yt, 0, h};
Point(5) = {-c, yt, 0, h};
Circle(1) = {2, 1, 3};  // inner face
Line(2) = {3, 4};       // right end
Circle(3) = {4, 1, 5};  // outer face
Line(4) = {5, 2};       // left end
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("left") = {4};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Surface("arch") = {1};
