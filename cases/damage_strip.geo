// A strip 2 mm long and 0.2 mm high (plane strain, nu = 0: a uniaxial stress), pulled at
// its right end on rollers. Lengths in mm; cells of 0.03 mm (their longest sides below
// ell/2 for damage_strip.toml).
L = 2; H = 0.2; h = 0.03;
Point(1) = {0, 0, 0, h};
Point(2) = {L, 0, 0, h};
Point(3) = {L, H, 0, h};
Point(4) = {0, H, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("left") = {4};
Physical Surface("strip") = {1};
