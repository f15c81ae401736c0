// Hertz contact on a Gmsh mesh: a quarter of a hemisphere (x >= 0, z >= 0), radius R = 5 mm,
// in millimetres; y is up, the apex at the origin and the flat face at y = R. Tetrahedra,
// graded: size lc_apex within r_fine of the apex (the contact radius of the test is 0.1 mm, 3 elements across it),
// growing by 0.3 per unit distance to lc_far.
//
// Second-order tetrahedra (tet10, six-node triangle faces, the mid-side nodes of the curved
// face on the sphere). The linear mesh of the comparison is the same mesh lowered to order 1
// (the same corner nodes and tetrahedra). Regenerate both (MSH 4.1, ASCII) with
//   python3 hertz-hemisphere.py
// (Python module `gmsh`, 4.15), or with the gmsh program:
//   gmsh hertz-hemisphere.geo -3 -o hertz-hemisphere-tet10.msh
//   gmsh hertz-hemisphere.geo -3 -order 1 -o hertz-hemisphere-tet4.msh
SetFactory("OpenCASCADE");

R = 5;
lc_apex = 0.033;
lc_far = 1.0;
r_fine = 0.2;

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

Physical Volume("cap") = {cap(0)};
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
