"""The example notebook (examples/python-row17.ipynb) runs top to bottom against the
test server: it submits the row17 example, waits with a progress bar and plots the worst
contact's force history."""

from __future__ import annotations

import os

import nbformat
import pytest
from nbclient import NotebookClient

from conftest import EXAMPLES, Server

NOTEBOOK = EXAMPLES / "python-row17.ipynb"


def test_the_row17_notebook_executes_and_plots_the_worst_contacts_force_history(
    server: Server, monkeypatch: pytest.MonkeyPatch
) -> None:
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    assert all(not cell.get("outputs") for cell in notebook.cells if cell.cell_type == "code"), (
        "the notebook is committed without outputs"
    )
    # The kernel inherits this process's environment: the notebook reads CHOCMODAL_URL.
    monkeypatch.setenv("CHOCMODAL_URL", server.url)
    monkeypatch.setenv("MPLBACKEND", "module://matplotlib_inline.backend_inline")
    NotebookClient(
        notebook, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(EXAMPLES)}}
    ).execute()

    outputs = [output for cell in notebook.cells if cell.cell_type == "code" for output in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "worst contact:" in text
    assert "100/100" in text, "the progress bar reached 100 %"
    images = [o for o in outputs if o.output_type == "display_data" and "image/png" in o.get("data", {})]
    assert len(images) == 1, "one figure: the worst contact's force history"
