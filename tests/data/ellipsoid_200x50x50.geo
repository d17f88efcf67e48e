// Source of ellipsoid_200x50x50.stl (test asset for the STL -> volume mesh route of fem_export):
// gmsh -2 -format stl -o ellipsoid_200x50x50.stl ellipsoid_200x50x50.geo   (Gmsh 4.8.4, units mm)
SetFactory("OpenCASCADE");
Sphere(1) = {0, 0, 0, 1};
Dilate {{0, 0, 0}, {200, 50, 50}} { Volume{1}; }
Mesh.Algorithm = 1;
Mesh.CharacteristicLengthMax = 22;
Mesh.CharacteristicLengthFromCurvature = 0;
