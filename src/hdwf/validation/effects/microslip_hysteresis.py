"""Micro-slip (partial-slip) friction in the torque path: a Masing/Iwan hysteresis element in series.

The parameter is what the data show, the same for every drive: the width of the hysteresis loop
at zero torque in the drive's own lost-motion test (0 -> +T -> 0 -> -T -> 0, T = 4 % of T_N).
The element is the Iwan/Masing element of density a = 2 w / T^2 (``hdwf.fe.cycle``): at the
realistic 0.2 arcmin, a = 126 µrad/(N m)^2 for HD 42 (T 0.96 N m) and 0.26 µrad/(N m)^2 for
HD 120 (T 21.16 N m).
"""

from dataclasses import replace

from hdwf.drive.geometry import ARCMIN

from . import Effect, Parameter

EFFECT = Effect(
    name="microslip_hysteresis",
    title="Micro-slip friction in the torque path (Masing/Iwan element)",
    description=(
        "Contacts along the drive's torque path are held by friction: the flexspline bore "
        "on the wave-generator bearing's outer ring, the flanks along the coned engagement "
        "of a real (3D) flexspline, the bolted faces of the flexspline-output and circular-"
        "spline-housing joints. Each holds back a little of the path's deformation until the "
        "tangential load on it reaches its slip limit mu N; as the torque grows more of them "
        "slip (micro-slip) and release their compliance; at a reversal they all stick again. "
        "The twist then lags the torque: a hysteresis loop that the frictionless section "
        "cannot make. In the model it is a lumped Iwan element in series at the output: "
        "springs bridged by Coulomb sliders, the compliance spread evenly over the slip "
        "torques, evaluated along the test's own torque sequence with the Masing rule. Its "
        "parameter is how that friction shows in the drive's lost-motion test: the loop width "
        "w at zero torque. The element's density (compliance per N m of slip torque) is then "
        "a = 2 w / T^2, T the test torque (at 0.2 arcmin: 126 µrad/(N m)^2 for HD 42, 0.26 "
        "for HD 120); first loading adds a T^2/2 = w at +-T, and the lost motion grows by 2 w."),
    signature=("a lens-shaped hysteresis loop: the unloading branch lies above the loading "
               "branch, the branches meet at +-T with the model's own slope; its width at zero "
               "torque is the parameter and the lost motion grows by twice that; no dead band"),
    parameters=(Parameter("loop_arcmin", "arcmin", 0.0, 1.5, 0.2,
                          "width of the hysteresis loop at zero torque in the drive's own "
                          "lost-motion test (0 -> +T -> 0 -> -T -> 0, T = 4 % T_N); the Iwan "
                          "element's density is a = 2 w / T^2", "linear"),),
    apply=lambda ch, loop_arcmin: replace(
        ch, output_microslip_loop_rad=ch.output_microslip_loop_rad + loop_arcmin * ARCMIN),
    series=True,
    references=("Iwan 1966 (distributed-element model of hysteresis); Masing 1926 (branches "
                "= virgin curve scaled by 2); Mindlin & Deresiewicz 1953 (partial slip); Dahl "
                "1968/1976 (solid friction); Taghirad & Bélanger 1998, Dhaouadi et al. 2003, "
                "Tjahjowidodo et al. 2013 (harmonic-drive hysteresis); realistic value: the "
                "catalogue compliance 1/K1 held by slip torques spread evenly up to the test "
                "torque, w = T/(2 K1), about 0.2 arcmin for every size (size 17, K1 0.81e4 "
                "N m/rad, at 0.96 N m: 0.20 arcmin)"),
    off={"loop_arcmin": 0.0},
)
