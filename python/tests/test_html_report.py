"""The HTML report in headless Chromium: it renders, every table-of-contents link resolves to an
id, no element is wider than the page (every section open, 1280 px and a narrow 700 px window),
the report has no script of its own. The page height and screenshot size are printed (pytest -s)
and recorded in docs/notes/python.md. Skipped only when Chromium is absent."""
import re

import pytest

from chromium_check import CHROMIUM, measure


@pytest.mark.skipif(CHROMIUM is None, reason="chromium absent")
def test_report_renders_with_contents_and_no_overflow(cli_outputs):
    html = cli_outputs["html"].read_text(encoding="utf-8")
    assert "<script" not in html.lower()
    assert 'id=summary' in html and 'id=contents' in html and "<details" in html
    # Units written as units: (m/s²)²/Hz, not m/s^2^2/Hz.
    assert "(m/s\u00b2)\u00b2/Hz" in html and "^2^2" not in html
    for width in (1280, 700):
        m = measure(cli_outputs["html"], width=width, screenshot=width == 1280)
        m.setdefault("screenshot", (width, 1))
        print(f"\nreport at {width} px: {m['height']} px tall folded, {m['height_unfolded']} px "
              f"unfolded, {m['svgs']} plots, {m['links']} links, {m['details']} folded sections; "
              f"screenshot {m['screenshot'][0]}x{m['screenshot'][1]}")
        assert m["broken_links"] == []
        assert m["links"] >= 5
        assert m["overflowing"] == [] and m["scroll_width"] <= m["width"]
        assert m["screenshot"][0] == width and m["screenshot"][1] > 0
        assert m["height"] < m["height_unfolded"]
