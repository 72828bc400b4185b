"""The report's figures: the ladder, the deformed teeth, the residual panels, the Sobol' convergence
and the knee, as drawn (axes, labels, panels)."""

import pytest


def test_the_ladder_figure_names_each_rungs_effect_and_shows_a_large_fall_on_a_log_axis(monkeypatch, tmp_path):
    """The paper campaigns fall 46x and 31x: on a linear axis the last two rungs sat on the floor,
    and the cumulative labels ('with preload, cup_torsion') overlapped. A fall beyond 10x (the
    noise line included) is drawn on a log axis; each tick names the effect its rung adds."""
    import matplotlib.pyplot as plt
    import pandas as pd

    from hdwf.report import figures

    drawn = []
    monkeypatch.setattr(figures, "_save", lambda fig, path: drawn.append(fig))
    models = ["baseline", "with preload", "with preload, cup_torsion"]
    figures.ladder_figure(pd.DataFrame({"model": models, "rmse_arcmin": [8.96, 0.52, 0.194]}), 0.19, "t", tmp_path / "a.png")
    figures.ladder_figure(pd.DataFrame({"model": ["baseline", "campaign model", "with thermal"],
                                        "rmse_arcmin": [0.31, 0.30, 0.052]}), 0.05, "t", tmp_path / "b.png")
    steep, shallow = (fig.axes[0] for fig in drawn)
    assert steep.get_yscale() == "log" and shallow.get_yscale() == "linear"     # 8.96/0.19 = 47; 0.31/0.05 = 6.2
    assert [t.get_text() for t in steep.get_xticklabels()] == ["baseline", "+ preload", "+ cup_torsion"]
    assert [t.get_text() for t in shallow.get_xticklabels()] == ["baseline", "campaign model", "+ thermal"]
    low, high = steep.get_ylim()
    assert low < 0.19 and high > 8.96                                           # every rung and the noise in view
    for fig in drawn:
        plt.close(fig)


def test_a_failed_rung_is_left_out_of_the_ladder_figure_not_labelled_nan(monkeypatch, tmp_path):
    """A rung whose solve failed has no RMSE (``ladder_table``): the figure labels the two rungs that
    have one and still puts the fall from 8.96 to 0.194 (46x) on a log axis."""
    import matplotlib.pyplot as plt
    import pandas as pd

    from hdwf.report import figures

    drawn = []
    monkeypatch.setattr(figures, "_save", lambda fig, path: drawn.append(fig))
    figures.ladder_figure(pd.DataFrame({"model": ["baseline", "with preload", "with preload, cup_torsion"],
                                        "rmse_arcmin": [8.96, float("nan"), 0.194]}), None, "t", tmp_path / "a.png")
    ax = drawn[0].axes[0]
    assert [t.get_text() for t in ax.texts] == ["8.96", "0.194"]
    assert ax.get_yscale() == "log"
    plt.close(drawn[0])


def test_the_deformed_picture_colours_the_stress_the_torque_adds(monkeypatch):
    """FS and CS given a uniaxial field of 100 MPa at +T and none at the mount: every FS and CS triangle in
    the window reads 100 MPa (a displacement colour would grow with x instead), the rings stay grey."""
    import numpy as np
    from matplotlib.collections import PolyCollection

    from hdwf.drive.geometry import drive_geometry
    from hdwf.drive.mesh import build_mesh
    from hdwf.fe.bodies import Material
    from hdwf.report import figures

    g = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.005, 0.005)
    mesh = build_mesh(g, 4, 3, 1.0, symmetry="half")
    E, nu = 210_000.0, 0.3
    plus = {name: np.vstack([100.0 / E * b.mesh.p[0], -nu * 100.0 / E * b.mesh.p[1]]) for name, b in mesh.bodies.items()}
    wg = {name: np.zeros_like(u) for name, u in plus.items()}
    drawn = []
    monkeypatch.setattr(figures, "_save", lambda fig, path: drawn.append(fig))
    figures.deformed_figure(mesh, {"plus": plus, "wg": wg}, Material(E, nu), "t", "x.png", half_width_mm=1.0,
                            xlim=(g.r_fs_bore - 0.5, g.r_cs_root + 0.5))
    coloured = [c for c in drawn[0].axes[0].collections if isinstance(c, PolyCollection) and c.get_array() is not None]
    assert len(coloured) == 1 and coloured[0].get_array().size > 100
    assert np.asarray(coloured[0].get_array()) == pytest.approx(100.0, rel=1e-9)
    assert drawn[0].axes[1].get_ylabel() == "von Mises stress added by the test torque (MPa)"
    # the wave generator pushes the bearing's outer ring out with the FS (0.17 mm on HD 42): a ring
    # moved into the window is drawn where it is, though its undeformed triangles lie outside it
    plus["or"] = plus["or"] + np.array([[0.3], [0.0]])
    outer = float(np.hypot(*mesh.bodies["or"].mesh.p).max())
    figures.deformed_figure(mesh, {"plus": plus, "wg": wg}, Material(E, nu), "t", "x.png", half_width_mm=1.0,
                            xlim=(outer + 0.05, g.r_cs_root + 0.5))
    grey = [c for c in drawn[1].axes[0].collections if isinstance(c, PolyCollection) and c.get_array() is None]
    assert sum(len(c.get_paths()) for c in grey) > 0


def test_the_residual_panels_stay_legible_at_page_width(monkeypatch):
    """Six panels in one row of an 18-inch figure printed at page width left 4-pt tick labels; three a
    row keep every panel about 3 inches wide. A curve campaign (five inputs and the curve) fills two
    rows; a Φ campaign's five inputs leave the sixth cell to the legend, clear of the data, and a
    curve campaign's legend goes in one row under the panels."""
    import numpy as np
    import pandas as pd

    from hdwf import PARAMETER_COLUMNS
    from hdwf.report import figures

    drawn = []
    monkeypatch.setattr(figures, "_save", lambda fig, path: drawn.append(fig))
    rng = np.random.default_rng(3)
    pts = pd.DataFrame({"specimen_id": np.repeat(["a", "b", "c"], 4), "D": rng.normal(size=12),
                        "S_model": rng.normal(size=12), "S_final": rng.normal(size=12),
                        **{c: np.repeat(rng.uniform(size=3), 4) for c in PARAMETER_COLUMNS},
                        "torque_Nm": np.tile([0.0, 0.96, 0.0, -0.96], 3), "branch": np.tile(["load+"] * 2 + ["load-"] * 2, 3)})
    figures.residual_figure(pts, "t", "a.png")
    figures.residual_figure(pts.drop(columns=["torque_Nm", "branch"]), "t", "b.png")
    for fig, with_data in zip(drawn, (6, 5)):
        assert len([ax for ax in fig.axes if ax.lines]) == with_data and len(fig.axes) == 6
        assert fig.get_figwidth() == 9 and len({ax.get_position().x0 for ax in fig.axes}) == 3   # 3 a row, page-wide
        # no legend drawn over a panel with data
        assert not [ax for ax in fig.axes if ax.lines and ax.get_legend() is not None]
    curve_fig, phi_fig = drawn
    # the curve campaign's legend names both models and the branches, under the panels
    assert [t.get_text() for t in curve_fig.legends[0].get_texts()] == ["campaign model", "with found effects",
                                                                         "load+", "load-"]
    spare = phi_fig.axes[5]
    assert not spare.axison and [t.get_text() for t in spare.get_legend().get_texts()] == [
        "campaign model", "with found effects"]


def test_the_sobol_convergence_figure_gives_each_input_its_own_panel(monkeypatch):
    """Two panels of 30 lines could not be told apart: one panel per input, each with both indices
    for every sampler and the exact values, the sixth cell the legend."""
    import pandas as pd

    from hdwf import PARAMETERS
    from hdwf.report import figures

    drawn = []
    monkeypatch.setattr(figures, "_save", lambda fig, path: drawn.append(fig))
    rows = [{"sampler": "exact", "parameter": p, "n": 0, "S1": 0.1 * i, "ST": 0.1 * i + 0.05}
            for i, p in enumerate(PARAMETERS)]
    rows += [{"sampler": s, "parameter": p, "n": n, "S1": 0.1 * i + 1 / n, "ST": 0.1 * i + 0.05 + 1 / n}
             for s in ("lhs", "halton", "sobol") for i, p in enumerate(PARAMETERS) for n in (64, 128, 256)]
    figures.sobol_convergence_figure(pd.DataFrame(rows), "t", "s.png")
    (fig,) = drawn
    panels = [ax for ax in fig.axes if ax.lines]
    assert len(panels) == 5 and len(fig.axes) == 6
    for ax, p in zip(panels, PARAMETERS):
        # 3 samplers × 2 indices, and the two exact lines
        assert len(ax.lines) == 8
        estimates = [ln for ln in ax.lines if len(ln.get_xdata()) == 3]
        assert sorted(float(ln.get_ydata()[-1]) for ln in estimates) == pytest.approx(
            sorted([0.1 * PARAMETERS.index(p) + 1 / 256] * 3 + [0.1 * PARAMETERS.index(p) + 0.05 + 1 / 256] * 3))
    assert len(fig.axes[5].get_legend().get_texts()) == 8


def test_the_knee_figure_is_linear_unless_a_panels_phi_spans_a_decade(monkeypatch):
    """A hinge is two straight pieces on a linear axis: the paper's 0.18–1.49 arcmin (8×) stays linear;
    a locked design at 0.02 beside open ones at 1.5 (75×) needs the log axis to be seen."""
    import numpy as np

    from hdwf.report import figures
    from hdwf.study.knee import HingeFit

    drawn = []
    monkeypatch.setattr(figures, "_save", lambda fig, path: drawn.append(fig))
    s = np.linspace(0, 50, 27)
    fit = HingeFit(0.18, 0.05, 25.0, (0.0, 0.0, 0.0), 1.0, 27)
    phi = 0.18 + 0.05 * np.maximum(0, s - 25)            # 0.18 to 1.43 arcmin: 7.9×
    locked = np.where(s < 25, 0.02, phi)                 # 0.02 to 1.43: 72×
    figures.knee_figure({"HD 42": {"paper": (s, phi, fit)}}, "t", "a.png")
    figures.knee_figure({"HD 42": {"ours": (s, locked, fit)}}, "t", "b.png")
    assert [fig.axes[0].get_yscale() for fig in drawn] == ["linear", "log"]
