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
