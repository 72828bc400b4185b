"""The flank layer's overlap integrated along the slave outline (``hdwf.fe.flank_layer``)."""
import numpy as np
import pytest

from hdwf.fe.flank_layer import LayerEdges


def _line(x: np.ndarray) -> LayerEdges:
    """Rows at the nodes ``x`` of a straight slave line, edges between neighbours; compliance
    times length 1 mm^2/N, so a row's force is its overlap times its share L of the integral."""
    n = x.size
    no_gap = np.full(n - 1, np.nan)
    return LayerEdges(a=np.arange(n - 1), b=np.arange(1, n), half_length=0.5 * np.diff(x),
                      gap_a=no_gap, gap_b=no_gap, per_length=np.ones(n))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_force_of_a_linear_overlap_is_its_area_on_any_nodes(seed):
    """An overlap falling linearly to zero, g(x) = k (x - x0), over a line from x = 0: the
    pressure g / c integrates to k x0^2 / 2 per unit c, and the rows' forces add up to that
    exactly wherever the nodes fall; half-edge lumping (every overlapping node with half of
    each of its edges) gives k x0 (x0 + h)/2-like sums that move with the nodes."""
    rng = np.random.default_rng(seed)
    x = np.concatenate([[0.0], np.sort(rng.uniform(0.0, 1.0, 6)), [1.0]])
    k, x0 = 0.02, 0.37
    gap = k * (x - x0)
    layer = _line(x)
    force = np.maximum(-gap, 0.0) / layer.compliance(gap)
    assert force.sum() == pytest.approx(0.5 * k * x0 ** 2, rel=1e-12)
    full = layer.per_length / layer.compliance(np.full(x.size, -1.0))  # every node overlapping
    lumped = (np.maximum(-gap, 0.0) * full).sum()
    assert abs(lumped / (0.5 * k * x0 ** 2) - 1) > 0.01


def test_a_uniform_overlap_keeps_each_node_half_its_edges():
    """Where both ends of every edge overlap, a node's share is half of each of its edges (the
    trapezoid rule, exact for a linear overlap): the same shares as the lumped rule."""
    x = np.array([0.0, 0.1, 0.25, 0.3, 0.5])
    layer = _line(x)
    share = 1.0 / layer.compliance(np.full(x.size, -2e-3))
    assert share == pytest.approx([0.05, 0.125, 0.1, 0.125, 0.1], rel=1e-12)
    gap = -1e-3 * (1.0 + x)             # linear, overlapping everywhere
    assert (-gap * share).sum() == pytest.approx(1e-3 * (0.5 + 0.5 ** 2 / 2), rel=1e-12)


def test_an_end_that_is_no_row_counts_with_its_gap():
    """A corner node overlapping by 3 um between two clear neighbours that are no rows (gaps 1 and
    5 um) has the two overlap triangles: L = h1/2 * 3/4 + h2/2 * 3/8; an end of unknown gap
    (-inf: not watched) counts as overlapping, its half edge whole."""
    layer = LayerEdges(a=np.array([-1, 0, -1]), b=np.array([0, -1, 0]),
                       half_length=np.array([0.02, 0.04, 0.01]),
                       gap_a=np.array([1e-3, np.nan, -np.inf]), gap_b=np.array([np.nan, 5e-3, np.nan]),
                       per_length=np.array([2.0]))
    s = layer.compliance(np.array([-3e-3]))
    assert 2.0 / s[0] == pytest.approx(0.02 * 0.75 + 0.04 * 0.375 + 0.01, rel=1e-12)


def test_a_mounted_preload_on_a_layer_holds_each_pair_at_its_share_of_the_overlap():
    """The solver's fixed point: at the mount of a preloaded drive on a flank layer (coarse half
    mesh), every loaded tooth pair's force is its overlap over the compliance its share of the
    overlap integral gives at the solved gaps (to the 0.1 % the shares are iterated to), and
    the layer's approach s p closes each loaded pair's gap (to the solver's 0.01 um)."""
    import dataclasses

    from hdwf.drive.geometry import drive_geometry
    from hdwf.drive.mesh import build_mesh
    from hdwf.fe import LostMotionModel
    from hdwf.fe.cycle import mount_wave_generator

    g = dataclasses.replace(drive_geometry("hd42", 31.0, 42.0, 0.015, 0.0, 0.0, interference_m=0.157,
                                           tip_relief=1.1), flank_layer_um_per_MPa=1.0)
    model = LostMotionModel(g, build_mesh(g, elements_over_height=5, elements_over_thickness=3,
                                          symmetry="half"), zone_deg=90.0)
    level = mount_wave_generator(model, ramp_teeth=True).solution
    rows = model.rows["tooth"]
    at = np.array([j for j, (kind, _) in enumerate(level.pair_ids) if kind == "tooth"])
    p, s = level.normal_force[at], level.row_compliance[at]
    geometric = rows.g0 + rows.G @ level.u_watch
    loaded = p > 1e-6 * p.max()
    assert loaded.sum() > 50
    assert np.abs(geometric[loaded] + s[loaded] * p[loaded]).max() < 2e-5
    share_force = np.maximum(-geometric, 0.0) / rows.layer.compliance(geometric)
    assert np.abs(share_force - np.where(loaded, p, 0.0)).max() < 2e-3 * p.max()
    # some pairs sit at the edge of a contact, where the share is less than half their edges
    lumped = rows.compliance
    assert np.sum(s[loaded] > 1.05 * lumped[loaded]) > 0


def test_a_layer_on_the_fs_pass_alone_drops_the_cs_tip_pass_only():
    """``flank_layer_fs_pass_only``: the tooth rows are the FS pass alone, its rows those of the two
    passes' FS pass (each overlap counted once, along the outline the layer's integral runs on);
    without the option, or without a layer, the CS tip-land pass is there too, so that a CS tip
    corner cannot sink into an FS flank between two FS nodes."""
    import dataclasses

    from hdwf.drive.geometry import drive_geometry
    from hdwf.drive.mesh import build_mesh
    from hdwf.fe import LostMotionModel, ModelChanges
    from hdwf.fe.contact_rows import tooth_rows
    from hdwf.fe.model import with_flank_layer

    g = drive_geometry("hd42", 31.0, 42.0, 0.015, 0.0, 0.0, interference_m=0.3, tip_relief=1.1, tip_round_m=0.1)
    model = LostMotionModel(g, build_mesh(g, elements_over_height=5, elements_over_thickness=3, symmetry="half"),
                            zone_deg=90.0)
    u = np.zeros(model.nwatch)
    both = tooth_rows(model.structure, with_flank_layer(g, ModelChanges(flank_layer_m=3800.0)), u, np.inf)
    one = with_flank_layer(g, ModelChanges(flank_layer_m=3800.0, flank_layer_fs_pass_only=True))
    assert one.flank_layer_fs_pass_only and one.flank_layer_um_per_MPa > 0
    fs_only = tooth_rows(model.structure, one, u, np.inf)
    no_layer = tooth_rows(model.structure, dataclasses.replace(g, flank_layer_fs_pass_only=True), u, np.inf)
    assert both.slave_nodes[1].size > 0 and no_layer.slave_nodes[1].size == both.slave_nodes[1].size
    assert fs_only.slave_nodes[1].size == 0
    assert np.array_equal(fs_only.slave_nodes[0], both.slave_nodes[0])
    n_fs = fs_only.slave_nodes[0].size
    assert fs_only.G.shape[0] == n_fs == fs_only.compliance.size
    assert abs(fs_only.G - both.G[:n_fs]).max() == 0.0
    np.testing.assert_array_equal(fs_only.compliance, both.compliance[:n_fs])
