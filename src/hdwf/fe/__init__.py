"""Our FE model of the lost-motion test: a 2D plane-stress section of the drive solved with
scikit-fem, with a contact solver written by hand (no maintained library solves frictional
node-to-segment contact on scikit-fem's matrices).  See ``docs/fe-model.md``.
"""

from hdwf.fe.model import (ContactFailure, LostMotionModel, LostMotionResult, ModelChanges,
                           assemble_stiffness, ball_compliance_coeff, edge_loads, hertz_point_contact,
                           plane_stress_lame, series_output_twist, solve_linear, solve_lost_motion,
                           solve_lost_motion_variants)

__all__ = ["ContactFailure", "LostMotionModel", "LostMotionResult", "ModelChanges", "assemble_stiffness",
           "ball_compliance_coeff", "edge_loads", "hertz_point_contact", "plane_stress_lame",
           "series_output_twist", "solve_linear", "solve_lost_motion", "solve_lost_motion_variants"]
