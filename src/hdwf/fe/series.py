"""Elements in series between the FS rim and the output where the twist is read.

A series element needs no contact solve: the output's twist is the solved rim twist plus the
element's, exactly, along the test's torque sequence (``series_output_twist``).  The elements
(``ModelChanges``): a torsional spring (the FS cup and diaphragm), a dead band (e.g. the wave
generator's Oldham coupling) and a micro-slip (Iwan) element (``microslip_twist``).
"""

from __future__ import annotations

import math

import numpy as np

from hdwf.fe.changes import ModelChanges


def microslip_twist(torque_Nmm: np.ndarray, density_rad_per_Nmm2: float) -> np.ndarray:
    """Twist of a micro-slip (Iwan) element along a load path, from the virgin state.

    The element is a chain of springs, each bridged by a Coulomb slider that holds it rigid
    while it sticks, with the chain's compliance spread evenly over the sliders' slip
    torques s: dc/ds = a.  The springs of the sliders of slip torque s carry the play
    operator of width s of the torque, p_s <- clip(p_s, T - s, T + s) from p_s = 0, and
    the twist is a * integral of p_s over s (a Prandtl-Ishlinskii operator).  On first
    loading that is a T|T|/2; after a reversal at (T_r, theta_r) it is theta_r +
    a (T - T_r)|T - T_r|/4, the virgin curve scaled by 2 about the reversal (Masing), and a
    branch that reaches an earlier reversal rejoins the branch it had left (Madelung's
    memory rule): the sliders do all of this by themselves.  In the test 0 -> +T -> 0 ->
    -T -> 0 the branches are a T^2/2 apart at zero torque.

    Exact: at every step p_s is piecewise linear in s with kinks only where s = |T_i| or
    2 s = |T_i - T_j| (T_i, T_j torques of the path), so the trapezoid rule over those s
    is the integral (p_s = 0 for every s beyond the largest |T|).

    Parameters
    ----------
    torque_Nmm : numpy.ndarray
        Torque at every step (N mm), starting from the virgin state.
    density_rad_per_Nmm2 : float
        a, the compliance per unit slip torque (rad per (N mm)^2).

    Returns
    -------
    numpy.ndarray
        Twist of the element at every step (rad).
    """
    T = np.asarray(torque_Nmm, dtype=float)
    out = np.zeros(T.size)
    if density_rad_per_Nmm2 == 0 or T.size == 0:
        return out
    levels = np.unique(T)
    half_gaps = 0.5 * np.abs(levels[:, None] - levels[None, :])
    s = np.unique(np.concatenate([[0.0], np.abs(levels), half_gaps.ravel()]))
    p = np.zeros(s.size)
    ds = np.diff(s)
    for k, torque in enumerate(T):
        p = np.clip(p, torque - s, torque + s)
        out[k] = density_rad_per_Nmm2 * 0.5 * float(np.sum((p[1:] + p[:-1]) * ds))
    return out


def series_output_twist(rim_twist_rad: np.ndarray, torque_Nmm: np.ndarray,
                        changes: ModelChanges) -> np.ndarray:
    """Twist at the output from the twist of the FS rim along the test sequence.

    The series spring adds T c, the dead band +-play/2 in the direction of the last
    non-zero load (the zero-torque steps keep the side they were loaded from), the
    micro-slip element its hysteretic twist along the torque sequence
    (``microslip_twist``).  The micro-slip element is given by its loop width w at zero
    torque in the lost-motion test (``output_microslip_loop_rad``); it is the Iwan element
    of density a = 2 w / max|T|^2, max|T| the peak torque of this sequence (the test torque
    on the test path), so that the test 0 -> +T -> 0 -> -T -> 0 shows a loop of exactly w.

    Parameters
    ----------
    rim_twist_rad : numpy.ndarray
        Twist of the FS rim at every step (rad).
    torque_Nmm : numpy.ndarray
        Torque at every step (N mm), from the first step of the test (the virgin state).
    changes : ModelChanges
        ``output_compliance_rad_per_Nmm``, ``output_play_rad`` and
        ``output_microslip_loop_rad`` are used.

    Returns
    -------
    numpy.ndarray
        Twist at the output at every step (rad).
    """
    out = np.asarray(rim_twist_rad, dtype=float) + changes.output_compliance_rad_per_Nmm * \
        np.asarray(torque_Nmm, dtype=float)
    if changes.output_play_rad:
        side, last = np.zeros(len(out)), 1.0
        for k, T in enumerate(torque_Nmm):
            if abs(T) > 0:
                last = math.copysign(1.0, T)
            side[k] = last
        out = out + 0.5 * changes.output_play_rad * side
    if changes.output_microslip_loop_rad:
        torque = np.asarray(torque_Nmm, dtype=float)
        peak = float(np.abs(torque).max()) if torque.size else 0.0
        if peak > 0:   # (no torque, no slip: the element adds nothing)
            out = out + microslip_twist(torque, 2.0 * changes.output_microslip_loop_rad / peak ** 2)
    return out
