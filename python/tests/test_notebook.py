"""The notebook of docs/notebooks runs headless: its code cells executed in order as one script
(no Jupyter needed), so that it cannot rot. Its own asserts check what it claims."""

import json
import pathlib

NOTEBOOK = pathlib.Path(__file__).resolve().parents[2] / "docs" / "notebooks" / "run_time_vs_error.ipynb"


def test_the_notebook_runs():
    cells = json.loads(NOTEBOOK.read_text())["cells"]
    code = [c["source"] for c in cells if c["cell_type"] == "code"]
    namespace = {}
    for source in code:
        text = source if isinstance(source, str) else "".join(source)
        exec(compile(text, str(NOTEBOOK), "exec"), namespace)
    figure = namespace["recording"].figure(view="sphere", stage=namespace["visible"], size=480)
    assert figure._repr_svg_().startswith("<svg")


LIGHT_FIT = NOTEBOOK.parent / "light_fit.ipynb"


def test_the_light_fit_converges():
    cells = json.loads(LIGHT_FIT.read_text())["cells"]
    namespace = {}
    for c in cells:
        if c["cell_type"] == "code":
            text = c["source"] if isinstance(c["source"], str) else "".join(c["source"])
            exec(compile(text, str(LIGHT_FIT), "exec"), namespace)
    # The notebook asserts the fit; here, that it converged to the true position within 1e-6.
    assert namespace["history"][-1][1] < 1e-6
