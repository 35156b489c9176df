"""Body names are text (issue 12, item 15).

A name with ``$...$`` was parsed as mathtext: every plot and the GIF export
failed (or drew something else than the name). The HTML template replaced
its placeholders one after the other, so a name containing ``__DATA__`` or
``__W__`` had the JSON data or the width substituted into the page title.
"""

import json
import re

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import eulerpoisson as ep  # noqa: E402
from eulerpoisson.viz import animate as an  # noqa: E402
from eulerpoisson.viz import plots  # noqa: E402

BAD_TEX = r"$x^{$ rod $\frac$"  # not valid mathtext: matplotlib raised ValueError while drawing
TEX = r"$\alpha$-rod $5"


@pytest.fixture(scope="module", params=[BAD_TEX, TEX])
def named(request):
    body = ep.RigidBody([3.0, 5.0, 8.0], name=request.param)
    return ep.solve(body, np.linspace(0.0, 20.0, 201), omega0=[0.0, 0.4, 0.00125])


@pytest.mark.parametrize("kind", plots.KINDS)
def test_every_plot_draws_the_name_as_typed(named, kind, tmp_path):
    out = tmp_path / f"{kind}.png"
    fig = plots.plot(named, kind, out=out)
    assert out.stat().st_size > 1000
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert titles
    title = titles[0]
    assert title.replace(r"\$", "$").count(named.body.name) == 1
    assert "$" not in title.replace(r"\$", "")  # every dollar escaped: no mathtext
    # what matplotlib draws: the name, literally
    from matplotlib.text import Text

    txt = next(t for ax in fig.axes for t in ax.findobj(Text) if t.get_text() == title)
    parts = txt._preprocess_math(txt.get_text())
    assert parts[1] is False and named.body.name in parts[0]


def test_gif_with_a_dollar_name(named, tmp_path):
    out = an.animate(named, tmp_path / "n.gif", fps=4, duration=1, size=(160, 120))
    assert out.stat().st_size > 0


def test_html_placeholders_in_a_name_are_text(tmp_path):
    name = "probe __DATA__ __W__ __H__ __TITLE__ <b>&"
    body = ep.RigidBody([3.0, 5.0, 8.0], name=name)
    tr = ep.solve(body, np.linspace(0.0, 20.0, 201), omega0=[0.0, 0.4, 0.00125])
    page = an.animate(tr, tmp_path / "p.html", size=(321, 123)).read_text()
    title = re.search(r"<title>(.*?)</title>", page, re.S).group(1)
    assert "__DATA__ __W__ __H__ __TITLE__ &lt;b&gt;&amp;" in title and len(title) < 200
    h1 = re.search(r"<h1>(.*?)</h1>", page, re.S).group(1)
    assert h1 == title.replace("Tumbling body: ", "")
    data = json.loads(re.search(r'<script type="application/json" id="ep-data">(.*?)</script>', page, re.S).group(1))
    assert data["title"].startswith(name)
    assert 'width="321" height="123"' in page and "width: 321px" in page
    assert page.count('id="ep-data"') == 1
