"""Renders an HTML report in headless Chromium and measures it: page height and width, elements
wider than the page, table-of-contents links without a target, <details> sections. The report
has no scripts; a copy with a measuring script appended is what Chromium loads."""
import json
import pathlib
import re
import shutil
import struct
import subprocess
import tempfile

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")

MEASURE = """<script>
(function () {
  const folded = document.documentElement.scrollHeight;
  for (const d of document.querySelectorAll('details')) d.open = true;
  const W = document.documentElement.clientWidth;
  const over = [];
  // An element inside a box that scrolls or clips horizontally (a wide table scrolls in its
  // own box) does not widen the page; every other element must end within it.
  const clipped = (e) => {
    for (let p = e.parentElement; p && p !== document.body; p = p.parentElement)
      if (getComputedStyle(p).overflowX !== 'visible') return true;
    return false;
  };
  for (const e of document.body.querySelectorAll('*')) {
    const r = e.getBoundingClientRect();
    if (r.right > W + 0.5 && clipped(e)) continue;
    if (r.right > W + 0.5) over.push(e.tagName + (e.id ? '#' + e.id : '') + ' ' + r.right);
  }
  const broken = [];
  const links = document.querySelectorAll('a[href^="#"]');
  for (const a of links) {
    if (!document.getElementById(decodeURIComponent(a.getAttribute('href').slice(1))))
      broken.push(a.getAttribute('href'));
  }
  const out = document.createElement('pre');
  out.id = 'geardiag-measure';
  out.textContent = JSON.stringify({
    height: folded, height_unfolded: document.documentElement.scrollHeight, width: W,
    scroll_width: document.documentElement.scrollWidth, overflowing: over.slice(0, 20),
    links: links.length, broken_links: broken, details: document.querySelectorAll('details').length,
    svgs: document.querySelectorAll('svg').length,
    images: document.querySelectorAll('svg image').length, scripts: %(scripts)d});
  document.body.appendChild(out);
})();
</script>"""


def measure(html_path, width=1280, screenshot=True):
    """Returns the measurements (dict) of the page at `width` CSS px: height as delivered
    (sections folded as the report folds them) and with every <details> opened; overflow and
    links with every section open; and the screenshot's (width, height) in pixels."""
    html = pathlib.Path(html_path).read_text(encoding="utf-8")
    scripts = len(re.findall(r"<script", html, re.I))
    with tempfile.TemporaryDirectory() as d:
        page = pathlib.Path(d) / "page.html"
        script = MEASURE % {"scripts": scripts}
        page.write_text(html.replace("</body>", script + "</body>"), encoding="utf-8")
        common = [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                  f"--window-size={width},900", "--user-data-dir=" + str(pathlib.Path(d) / "u")]
        dom = subprocess.run(common + ["--dump-dom", page.as_uri()], check=True,
                             capture_output=True, text=True, timeout=120).stdout
        m = re.search(r'<pre id="geardiag-measure">(.*?)</pre>', dom, re.S)
        result = json.loads(m.group(1).replace("&quot;", '"').replace("&amp;", "&"))
        if not screenshot:
            return result
        shot = pathlib.Path(d) / "shot.png"
        subprocess.run(common + [f"--screenshot={shot}", pathlib.Path(html_path).resolve().as_uri()],
                       check=True, capture_output=True, timeout=120)
        w, h = struct.unpack(">II", shot.read_bytes()[16:24])  # PNG IHDR
        result["screenshot"] = (w, h)
    return result


if __name__ == "__main__":
    import sys
    for p in sys.argv[1:]:
        print(p, json.dumps(measure(p)))
