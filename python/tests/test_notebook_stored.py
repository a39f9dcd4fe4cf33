"""examples/pound_tour.ipynb is stored as source: valid nbformat 4 JSON,
no outputs, no execution counts (python/check.sh executes it)."""
import json

from conftest import REPO

NOTEBOOK = REPO / "python" / "examples" / "pound_tour.ipynb"


def test_notebook_is_stored_without_outputs():
    nb = json.loads(NOTEBOOK.read_text())
    assert nb["nbformat"] == 4 and nb["metadata"]["kernelspec"]["language"] == "python"
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert len(code) >= 8
    for c in code:
        assert c["outputs"] == [] and c["execution_count"] is None, "".join(c["source"])[:60]
    text = "".join("".join(c["source"]) for c in nb["cells"])
    for what in ("pound.spectrum(", "pound.plot.spectrum(", "three-buildings.json",
                 "Scene.chain(", "NGA_no_1063_RRS228.AT2", "pound.plot.history("):
        assert what in text
