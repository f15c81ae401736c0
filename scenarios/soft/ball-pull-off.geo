// A quarter of a soft hemisphere (x >= 0, z >= 0), radius R = 5 mm, in millimetres; y is up,
// the apex at the origin and the flat face at y = R. Second-order tetrahedra (tet10, the
// mid-side nodes of the curved face on the sphere), graded: size lc_apex within r_fine of
// the apex, growing by 0.3 per unit distance to lc_far.
//
// Regenerate the mesh (MSH 4.1, ASCII) with
//   gmsh ball-pull-off.geo -3 -o ball-pull-off.msh
// or with the Python module (pip install gmsh):
//   python3 -c "import gmsh; gmsh.initialize(); gmsh.open('ball-pull-off.geo'); \
//     gmsh.model.mesh.generate(3); gmsh.write('ball-pull-off.msh'); gmsh.finalize()"
SetFactory("OpenCASCADE");

R = 5;
lc_apex = 0.25;
lc_far = 1.5;
r_fine = 1.0;

Sphere(1) = {0, R, 0, R};
Box(2) = {0, 0, 0, R + 1, R, R + 1};
cap() = BooleanIntersection{ Volume{1}; Delete; }{ Volume{2}; Delete; };

e = 1e-3;
top() = Surface In BoundingBox{-e, R - e, -e, R + e, R + e, R + e};
sym_x() = Surface In BoundingBox{-e, -e, -e, e, R + e, R + e};
sym_z() = Surface In BoundingBox{-e, -e, -e, R + e, R + e, e};
all() = Boundary{ Volume{cap(0)}; };
curved() = all();
curved() -= top();
curved() -= sym_x();
curved() -= sym_z();

Physical Volume("ball") = {cap(0)};
Physical Surface("top") = {top()};
Physical Surface("sym_x") = {sym_x()};
Physical Surface("sym_z") = {sym_z()};
Physical Surface("curved") = {curved()};

apex = newp;
Point(apex) = {0, 0, 0};
Field[1] = Distance;
Field[1].PointsList = {apex};
Field[2] = MathEval;
Field[2].F = Sprintf("min(%g, max(%g, %g + 0.3 * (F1 - %g)))", lc_far, lc_apex, lc_apex, r_fine);
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.ElementOrder = 2;
Mesh.MshFileVersion = 4.1;
Mesh.Binary = 0;
Mesh.RandomSeed = 1;
