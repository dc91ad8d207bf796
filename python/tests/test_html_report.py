"""The HTML report in headless Chromium: it renders, every table-of-contents link resolves to an
id, no element is wider than the page (every section open, in a narrow 700 px window),
the report has no script of its own. The page height and screenshot size are printed (pytest -s)
and recorded in docs/notes/python.md. Skipped only when Chromium is absent."""

import pytest

from chromium_check import CHROMIUM, measure


@pytest.mark.skipif(CHROMIUM is None, reason="chromium absent")
def test_report_renders_with_contents_and_no_overflow(cli_outputs):
    html = cli_outputs["html"].read_text(encoding="utf-8")
    assert "<script" not in html.lower()
    assert "Kurtogram" in html and "Time waveform" in html and "Difference signal" in html
    assert 'id=summary' in html and 'id=contents' in html and "<details" in html
    # Units written as units: (m/s²)²/Hz, not m/s^2^2/Hz.
    assert "(m/s\u00b2)\u00b2/Hz" in html and "^2^2" not in html
    # 700 CSS px: narrower than the plots (820 px) and the widest tables, so that an element
    # that does not shrink or scroll in its own box shows.
    m = measure(cli_outputs["html"], width=700)
    print(f"\nreport at 700 px: {m['height']} px tall folded, {m['height_unfolded']} px unfolded, "
          f"{m['svgs']} plots, {m['links']} links, {m['details']} folded sections; screenshot "
          f"{m['screenshot'][0]}x{m['screenshot'][1]}")
    assert m["broken_links"] == []
    assert m["links"] >= 5
    assert m["overflowing"] == [] and m["scroll_width"] <= m["width"]
    assert m["screenshot"][0] == 700 and m["screenshot"][1] > 0
    assert m["height"] < m["height_unfolded"]
