"""The notebook-style example of docs/python.md runs as written (from a checkout whose
../shared/data holds the CWRU files) and finds the inner-race fault."""
import contextlib
import io
import os
import pathlib
import re

import pytest

from conftest import SHARED_DATA, SOURCE

DOC = SOURCE / "docs" / "python.md"


@pytest.mark.skipif(not (SHARED_DATA / "cwru-bearing" / "IR007_0.mat").exists(),
                    reason="CWRU data absent")
def test_docs_example_runs_as_written(tmp_path):
    code = re.search(r"```python\n(.*?)```", DOC.read_text(), re.S).group(1)
    # A checkout beside the shared data: tmp/checkout and tmp/shared/data -> the real one.
    checkout = tmp_path / "checkout"
    checkout.mkdir()
    (tmp_path / "shared").mkdir()
    (tmp_path / "shared" / "data").symlink_to(SHARED_DATA.resolve())
    out = io.StringIO()
    cwd = os.getcwd()
    try:
        os.chdir(checkout)
        with contextlib.redirect_stdout(out):
            exec(compile(code, str(DOC), "exec"), {"__name__": "__main__"})
    finally:
        os.chdir(cwd)
    text = out.getvalue()
    assert "bearing drive_end inner_race 162.09 Hz" in text, text
    png = checkout / "cwru_ir007_envelope.png"
    assert png.stat().st_size > 10000
