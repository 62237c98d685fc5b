"""Every plot of the study's report keeps its text inside its canvas, and no title or label
prints a Python list (issue 34): rendered, each figure's tight bounding box (every artist:
titles, labels, legends, colour bars) must lie within the figure."""

from __future__ import annotations

import re

import pytest

from compare.verify.study import run_study
from spindle.spec_reader import load_spec

#: a rounding margin of the renderer [inches]: a tenth of a point
SLACK_IN = 0.1 / 72


@pytest.fixture(scope="module")
def study():
    # small and fast (as tests/test_study_executor.py): three levels, two node counts
    return run_study(load_spec("fin-shaft"), levels=(0, 1, 2), nodes=(3, 11), dt_s=600.0)


def _figures(study):
    acc = [a for a in (study.steady, study.transient) if a is not None]
    yield "convergence", study.convergence.plot().figure
    for a in acc:
        tag = "transient" if a.transient else "steady"
        yield f"{tag} error", a.plot().figure
        yield f"{tag} runtime", a.plot(against="runtime").figure
        yield f"{tag} profile", a.profile_plot().figure


def test_every_report_plot_keeps_its_text_inside_the_canvas(study):
    from spindle.plots import pyplot

    plt = pyplot()
    for name, fig in _figures(study):
        fig.canvas.draw()
        tight = fig.get_tightbbox(fig.canvas.get_renderer())
        w, h = fig.get_size_inches()
        assert tight.x0 >= -SLACK_IN and tight.y0 >= -SLACK_IN, (name, tight)
        assert tight.x1 <= w + SLACK_IN and tight.y1 <= h + SLACK_IN, (name, tight, (w, h))
        texts = [t.get_text() for t in fig.findobj(lambda a: hasattr(a, "get_text"))]
        assert not [t for t in texts if re.search(r"\[\d+(, \d+)+\]", t)], (name, texts)
        plt.close(fig)


def test_the_x_axis_names_only_what_ran(study):
    """Without a reduced model the unknowns axis does not mention ROM states."""
    ax = study.steady.plot()
    assert "ROM" not in ax.get_xlabel()


@pytest.fixture(scope="module")
def steady_spl():
    """spl2782's steady nominal point on level 0 with its growth (a few seconds)."""
    from reference import ReferenceModel

    return ReferenceModel(load_spec("spl2782"), 0).steady("nominal")


def test_the_deformation_colour_bar_has_one_scale_both_ways(steady_spl):
    """A micrometre is the same colour step forwards and backwards: the colour bar of the
    axial displacement runs from -m to +m, m the largest |u_z|, so white is 'does not
    move' (issue 34: a bar with two slopes drew 0 -> +90 um as tall as 0 -> -330 um)."""
    import numpy as np

    from reference.fields import add_displacement, field_grid
    from reference.plots import deformed_figure
    from spindle.plots import pyplot

    res = steady_spl
    grid = field_grid(res.model, res.T)
    add_displacement(grid, res.elastic, res.U)
    fig = deformed_figure(grid, "nominal", res.growth_m)
    mappable = fig.axes[0].collections[-1]
    lo, hi = mappable.norm.vmin, mappable.norm.vmax
    span = float(np.abs(grid.point_data["u_z_um"]).max())
    assert lo == -hi and hi == pytest.approx(span, rel=1e-12)
    bar = fig.axes[1]  # the colour bar's own axes: its scale is the norm's, linear
    assert bar.get_ylim() == pytest.approx((lo, hi), rel=1e-9)
    pyplot().close(fig)


def test_the_3d_colour_bar_labels_whole_degrees(steady_spl):
    """The 3-D picture's colour bar prints whole degrees ('122', not VTK's default '122.' or
    '1.22e+02'): the label format of the bar as it is drawn."""
    from reference.plots import revolved_plotter

    pl = revolved_plotter(steady_spl.model, steady_spl.T, "nominal", window=(400, 300))
    pl.render()
    bar = pl.scalar_bars["T [°C]"]
    assert bar.GetLabelFormat() == "%.0f"
    lo, hi = bar.GetLookupTable().GetRange()
    assert hi - lo > 1.0  # degrees apart enough for whole-degree labels to differ
    pl.close()
