"""The HTML report in headless Chromium: it renders, every table-of-contents link resolves to an
id, no element is wider than the page (every section open, in a narrow 700 px window),
the report has no script of its own. The page height and screenshot size are printed (pytest -s)
and recorded in docs/report.md. Skipped only when Chromium is absent."""

import base64
import re
import struct
import zlib

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
    # Every spectrogram image is an element of an SVG Chromium drew.
    assert m["images"] == html.count('href="data:image/png;base64,') > 0


def _png_chunks(data):
    """(type, payload) of each chunk of a PNG, every CRC checked (zlib.crc32: the PNG CRC)."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    at, out = 8, []
    while at < len(data):
        (n,) = struct.unpack(">I", data[at:at + 4])
        kind, payload = data[at + 4:at + 8], data[at + 8:at + 8 + n]
        assert struct.unpack(">I", data[at + 8 + n:at + 12 + n])[0] == zlib.crc32(kind + payload)
        out.append((kind, payload))
        at += 12 + n
    return out


def test_spectrograms_are_valid_pngs_on_the_bounded_grid(cli_outputs, sim_recording):
    """The spectrogram of each channel section is an 8-bit palette PNG (CRCs and the zlib stream
    checked with the standard library) of at most 240 time columns x 129 frequency rows, whatever
    the record's length, using more than one colour."""
    html = cli_outputs["html"].read_text(encoding="utf-8")
    uris = re.findall(r'href="data:image/png;base64,([A-Za-z0-9+/=]+)"', html)
    assert len(uris) == html.count("Spectrogram (Hann")
    for u in uris:
        chunks = dict(_png_chunks(base64.b64decode(u)))
        w, h, depth, colour = struct.unpack(">IIBB", chunks[b"IHDR"][:10])
        assert (depth, colour) == (8, 3) and 2 <= w <= 240 and h == 129
        assert len(chunks[b"PLTE"]) == 3 * 256
        raw = zlib.decompress(chunks[b"IDAT"])
        assert len(raw) == h * (w + 1)
        assert len(set(raw[1:w + 1])) > 1
    print(f"\n{len(uris)} spectrograms, {sum(len(u) for u in uris)} base64 characters; "
          f"report {len(html)} characters")
