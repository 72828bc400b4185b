"""A curve point meets the model at its measured torque, on the branch of the same kind: the
model's own points come back exactly, points between its steps by linear interpolation, and a
test run −T first meets the mirror image of the model's test."""

import numpy as np
import pandas as pd
import pytest

from hdwf.fe import torque_fractions
from hdwf.validation.observations import branch_twist, predict, twist_along_test

TEST_TORQUE = 0.96
RNG = np.random.default_rng(3)
MODEL_T = TEST_TORQUE * torque_fractions(4)               # 17 steps
MODEL_TWIST = np.cumsum(RNG.normal(0.0, 1.0, MODEL_T.size))  # any curve: the lookup must not care


def _table(sid="S1"):
    return pd.DataFrame({"specimen_id": sid, "variant": "base", "step": np.arange(MODEL_T.size),
                         "torque_Nm": MODEL_T, "twist_arcmin": MODEL_TWIST, "status": "ok"})


def _obs(torque, steps=None, sid="S1"):
    steps = np.arange(len(torque)) if steps is None else steps
    return pd.DataFrame({"specimen_id": sid, "step": steps, "torque_Nm": torque, "D": 0.0,
                         "quantity": "twist", "u_D": np.nan})


def test_the_model_own_points_come_back_exactly():
    assert np.array_equal(predict(_table(), _obs(MODEL_T), "base"), MODEL_TWIST)


def test_points_between_model_steps_are_interpolated_on_their_branch():
    """8 steps per ramp measured, 4 solved: the odd points lie halfway between two model points
    of the same branch, so they get the mean of the two (linear in |T|)."""
    got = branch_twist(MODEL_T, MODEL_TWIST, TEST_TORQUE * torque_fractions(8))
    assert np.array_equal(got[::2], MODEL_TWIST)
    halfway = (MODEL_TWIST[:-1] + MODEL_TWIST[1:]) / 2
    assert got[1::2] == pytest.approx(halfway, abs=1e-12)


def test_a_test_run_minus_T_first_is_the_mirror_image_of_the_model_test():
    """0 → −T → 0 → +T → 0 is the model's test mirrored through the major axis (section and
    effects are symmetric under it, and the model leans towards its first load at zero torque):
    the point measured at −t on the first ramp meets minus the model's twist at +t."""
    assert np.array_equal(predict(_table(), _obs(-MODEL_T), "base"), -MODEL_TWIST)
    # off the model's steps too
    fine = TEST_TORQUE * torque_fractions(8)
    assert np.array_equal(twist_along_test(MODEL_T, MODEL_TWIST, -fine), -branch_twist(MODEL_T, MODEL_TWIST, fine))


def test_steps_are_read_as_the_order_of_the_test_not_the_row_order():
    shuffled = RNG.permutation(MODEL_T.size)
    obs = _obs(MODEL_T[shuffled], steps=shuffled)
    assert np.array_equal(predict(_table(), obs, "base"), MODEL_TWIST[shuffled])


def test_phi_and_lost_motion_are_read_at_the_test_torques():
    obs = pd.DataFrame({"specimen_id": "S1", "quantity": ["phi_plus", "phi_minus", "lost_motion"], "D": 0.0})
    kp, km = 4, 12
    assert predict(_table(), obs, "base") == pytest.approx(
        [MODEL_TWIST[kp], -MODEL_TWIST[km], MODEL_TWIST[kp] - MODEL_TWIST[km]])
