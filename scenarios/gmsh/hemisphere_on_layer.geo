// A soft hemisphere (tetrahedra) above an elastic layer (hexahedra), in millimetres; y is up.
// Two physical volumes in one file: a scenario takes each as its own body with
// `mesh = { file = "hemisphere_on_layer.msh", volumes = ["ball"], scale = 1e-3 }`.
//
// Regenerate the mesh (MSH 4.1, ASCII) with
//   gmsh hemisphere_on_layer.geo -3 -format msh41 -o hemisphere_on_layer.msh
SetFactory("OpenCASCADE");

R = 10;      // hemisphere radius
gap = 0.1;   // initial gap between the hemisphere's apex and the layer
L = 15;      // half width of the layer
H = 4;       // layer thickness
lc = 2.5;    // tetrahedron size in the hemisphere
N = 12;      // hexahedra along each side of the layer
NH = 2;      // hexahedra through the layer

// Hemisphere: flat face at y = R + gap, apex at (0, gap, 0).
Sphere(1) = {0, R + gap, 0, R};
Box(2) = {-R - 1, gap - 1, -R - 1, 2 * R + 2, R + 1, 2 * R + 2};
ball() = BooleanIntersection{ Volume{1}; Delete; }{ Volume{2}; Delete; };

// Layer: a structured quadrangle mesh of its bottom face (y = -H) extruded upwards.
p1 = newp; Point(p1) = {-L, -H, -L};
p2 = newp; Point(p2) = { L, -H, -L};
p3 = newp; Point(p3) = { L, -H,  L};
p4 = newp; Point(p4) = {-L, -H,  L};
c1 = newc; Line(c1) = {p1, p2};
c2 = newc; Line(c2) = {p2, p3};
c3 = newc; Line(c3) = {p3, p4};
c4 = newc; Line(c4) = {p4, p1};
cl = newcl; Curve Loop(cl) = {c1, c2, c3, c4};
bottom = news; Plane Surface(bottom) = {cl};
Transfinite Curve{c1, c2, c3, c4} = N + 1;
Transfinite Surface{bottom};
Recombine Surface{bottom};
layer[] = Extrude{0, H, 0}{ Surface{bottom}; Layers{NH}; Recombine; };

e = 1e-3;
ball_top() = Surface In BoundingBox{-R - e, R + gap - e, -R - e, R + e, R + gap + e, R + e};
ball_all() = Boundary{ Volume{ball(0)}; };
ball_curved() = ball_all();
ball_curved() -= ball_top();

Physical Volume("ball") = {ball(0)};
Physical Volume("layer") = {layer[1]};
Physical Surface("ball_top") = {ball_top()};
Physical Surface("ball_surface") = {ball_curved()};
Physical Surface("layer_top") = {layer[0]};
Physical Surface("layer_bottom") = {bottom};

MeshSize{ PointsOf{ Volume{ball(0)}; } } = lc;
Mesh.MeshSizeFromCurvature = 12;
Mesh.ElementOrder = 1;
Mesh.MshFileVersion = 4.1;
