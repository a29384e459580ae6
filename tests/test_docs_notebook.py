"""docs/notebooks.md run as a notebook in a real Jupyter kernel (nbclient + ipykernel), issue 31.

Its ```python blocks become the cells of one notebook, executed in order; no cell may raise, each
``print(...)  # -> text`` line must print that text (as in tests/test_docs.py), and a robot left as a cell's
value is shown by Jupyter as its rich display (an HTML table).  Skips without nbclient/ipykernel.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from test_docs import _PRINTS, _norm, doc_blocks

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "notebooks.md"


@pytest.mark.slow
def test_notebooks_page_runs_in_a_jupyter_kernel(tmp_path):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")
    blocks = [b for b in doc_blocks(DOC) if b.lang == "python" and not b.skip]
    assert len(blocks) >= 5
    setup = (f"import os, sys\nos.environ['MPLBACKEND'] = 'Agg'\nsys.path.insert(0, {str(ROOT / 'src')!r})\n"
             "import denavit\nassert denavit.__file__.startswith(sys.path[0]), denavit.__file__")
    cells = [setup] + [b.text for b in blocks] + ["denavit.load_robot('planar2r')"]
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(c) for c in cells])
    nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                            resources={"metadata": {"path": str(tmp_path)}}).execute()  # raises on a cell's error
    for block, cell in zip(blocks, nb.cells[1:-1]):
        printed = [_norm(line) for out in cell.outputs if out.get("name") == "stdout"
                   for line in out["text"].splitlines()]
        for shown in _PRINTS.findall(block.text):
            assert _norm(shown) in printed, f"docs/notebooks.md:{block.line}: shows {shown!r}, printed {printed}"
    (shown,) = [out for out in nb.cells[-1].outputs if out["output_type"] == "execute_result"]
    assert "<table" in shown["data"]["text/html"] and "planar2r" in shown["data"]["text/plain"]
