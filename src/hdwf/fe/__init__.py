"""Our FE model of the lost-motion test: a 2D plane-stress section of the drive solved with
scikit-fem, with a contact solver written by hand (no maintained library solves frictional
node-to-segment contact on scikit-fem's matrices).  See ``docs/fe-model.md``.

The test: wave generator locked, CS held, the torque sequence 0 -> +T -> 0 -> -T -> 0 on
the FS rim; the result is the torque-twist curve, phi (+T), phi' (-T) and the lost motion
Phi = phi + phi'.  The modules, from the bottom up:

* ``changes``: ``ModelChanges``, the physical additions to the baseline model;
* ``hertz``: the Hertz law of a bearing ball and its contact pressure;
* ``bodies``: plane-stress stiffness, factorisation, rigid modes and half-model ties;
* ``structure``: the bodies seen through the watch vector, the torque load and twist measure;
* ``contact_geometry`` and ``contact_rows``: closest points and normals on the contact
  surfaces, and the linearised gaps of cam, balls, fit and teeth;
* ``flank_layer``: a compliant layer between the flanks, each tooth pair's compliance from its
  share of the overlap integrated along the slave outline;
* ``column_store``, ``node_columns``, ``working_set`` and ``friction``: compliance columns kept
  in chunks a fork shares, the responses kept per tooth node, the cached compliance of the
  working set, and the flank law (frictionless or Coulomb) with its own cache and stick/slip state;
* ``ring_columns``: the FS's and CS's columns turned from one tooth period's (their stiffness
  commutes with the turn by a period), so only the first periods' loads are back-substituted;
* ``active_factor``: the dense KKT solves of an active set, with the Cholesky factor of its
  compliance kept while only part of its diagonal moves (the layer's and the balls' iteration);
* ``solver``: the active-set contact solver of one load level, at a torque or a prescribed twist;
* ``relinearise``: the tooth and cam rows re-detected at a solved state until they agree;
* ``model``: ``LostMotionModel``, which assembles the pieces for one design;
* ``preload``: the preload ramp that mounts preloaded teeth (``DriveGeometry.preloaded``: a flank
  allowance ``interference_m`` or a deeper cam ``deflection_coeff``), and the
  check of the teeth outside the watched zones;
* ``series``: elements in series between the FS rim and the output (spring, dead band, micro-slip);
* ``cycle``: the test itself, ``solve_lost_motion`` and ``solve_lost_motion_variants``;
* ``coning``: the quasi-3D cup, slices along the face width on one twist (``ModelChanges.coning_slope``).
* ``stress``: the von Mises stress of a displacement field, element by element (the report's picture).

Half model (``mesh.symmetry == "half"``, hand-written): the drive and its load are
invariant under the rotation by pi about the axis (even tooth and ball counts, pi-periodic
cam, torque), so the solution satisfies u(-x) = -u(x) and only the upper half of every
body is meshed (``hdwf.drive.mesh``).  The cut is tied (``bodies``), contacts cover [0, pi)
(``contact_rows``), the half rim carries T/2 (``structure``) and the tooth count is doubled
(``cycle``).  Both models give the same Phi to mesh noise (two different gmsh meshes of one
density).

Approximations (known): P1 triangles (with preloaded teeth Phi moves by up to about 6 % between
1x and 1.25x the paper's density, see docs/fe-model.md, "Mesh convergence"); the fit bins compare the
two surfaces at equal reference angles (their relative slide of ~10 um on a surface slope
<= 0.017 shifts those gaps by < 0.2 um, the same for every design); ball 0 sits on the
major axis (one sample of the WG angle).  Friction, cup torsion, housing compliance,
a temperature difference and Oldham play are off in the baseline (``ModelChanges``).
"""

from hdwf.fe.bodies import assemble_stiffness, edge_loads, plane_stress_lame, solve_linear
from hdwf.fe.changes import ModelChanges
from hdwf.fe.cycle import (LostMotionResult, solve_lost_motion,
                           solve_lost_motion_variants, torque_fractions)
from hdwf.fe.hertz import (ISO76_BALL_PRESSURE_MPA, ball_compliance_coeff, ball_max_pressure,
                            hertz_max_pressure, hertz_point_contact)
from hdwf.fe.model import LostMotionModel
from hdwf.fe.series import series_output_twist
from hdwf.fe.solver import ContactFailure

__all__ = ["ISO76_BALL_PRESSURE_MPA", "ContactFailure", "LostMotionModel", "LostMotionResult", "ModelChanges",
           "assemble_stiffness", "ball_compliance_coeff", "ball_max_pressure", "edge_loads", "hertz_max_pressure",
           "hertz_point_contact", "plane_stress_lame",
           "series_output_twist", "solve_linear", "solve_lost_motion", "solve_lost_motion_variants",
           "torque_fractions"]
