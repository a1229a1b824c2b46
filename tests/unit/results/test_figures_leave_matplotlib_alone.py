"""Drawing the package's figures leaves the caller's matplotlib as it was.

A user who draws a mode from a notebook or a GUI session keeps the backend and the
settings they chose: the figures are :class:`matplotlib.figure.Figure` objects of their
own, not pyplot's (matplotlib's "embedding" usage), so nothing global changes.
"""

import tomllib

import pytest

SMALL = """\
name = "small"
[plate]
corners = [[-0.1, -0.05], [0.1, 0.05]]
thickness = 0.006
[material]
E = 1.0e9
nu = 0.3
[mesh]
nx = 6
ny = 4
"""


@pytest.fixture
def users_matplotlib():
    """The user's pyplot: the SVG backend, a font size of their own; restored after."""
    mpl = pytest.importorskip("matplotlib")
    import matplotlib.pyplot as plt

    backend = mpl.get_backend()
    with mpl.rc_context({"font.size": 7.0}):
        plt.switch_backend("svg")
        try:
            yield mpl, plt
        finally:
            plt.close("all")
            plt.switch_backend(backend)


def _unchanged(mpl, plt):
    assert mpl.get_backend() == "svg"
    assert mpl.rcParams["font.size"] == 7.0
    assert plt.get_fignums() == []


def test_the_mode_and_convergence_figures_leave_matplotlib_alone(tmp_path, users_matplotlib):
    """Before: the first figure switched the backend to Agg and set font.size globally."""
    from unibuckle_fenicsx.viz.plotting import plot_convergence, plot_section

    mpl, plt = users_matplotlib
    x = [0.0, 0.5, 1.0]
    w = [0.0, -1.0, 0.0]
    section = plot_section(tmp_path / "s.png", x, w, x, w, zone_x=(0.2, 0.8))
    studies = {"free": [(4, 2, 1.2e6), (8, 4, 1.1e6), (16, 8, 1.05e6)]}
    convergence = plot_convergence(tmp_path / "c.png", studies, reference=1.0e6)
    _unchanged(mpl, plt)
    for path in (section, convergence):
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_sweep_chart_leaves_matplotlib_alone(tmp_path, users_matplotlib):
    """Before: ``plot_sweep`` switched the backend to Agg and left its figure open."""
    from unibuckle_fenicsx.sweep import parse_variation
    from unibuckle_fenicsx.viz.charts import plot_sweep

    mpl, plt = users_matplotlib
    lines = [
        {"point": {"plate.length": a}, "status": "ok", "buckling_coefficient_k": 4.4,
         "free_load_Pa": 1.0, "critical_load_Pa": 1.1, "certificate": None}
        for a in (0.2, 0.3)
    ]  # fmt: skip
    variation = [parse_variation("plate.length=0.2,0.3")]
    path = plot_sweep(lines, variation, tomllib.loads(SMALL), tmp_path / "k.png")
    _unchanged(mpl, plt)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
