"""The drive: a design row becomes a geometry, the geometry a gmsh mesh.

``geometry`` holds each drive's constants and the tooth shapes, ``cam`` the wave generator's cam
(the paper's Eq. 3), ``relief`` the tip relief the teeth's path needs, ``mesh`` builds the
plane section in gmsh (``sector_mesh``: the toothed rings as one tooth period copied round;
``gmsh_read``: a meshed surface read out as arrays), ``design`` joins them (design parameters -> geometry -> mesh, with the
mesh settings in one dataclass) and stores a mesh for the solver.
"""
