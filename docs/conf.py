"""Sphinx configuration of the fenics-nl documentation (`make docs`: no network needed).

The demos' pages are notebooks executed beforehand by docs/notebooks.py (Sphinx executes
nothing); the benchmark tables in benchmarks.md are written by the benchmark scripts
(`--update-docs`) from benchmarks/results/*.json.
"""

import sysconfig
from pathlib import Path

project = "fenics-nl"
author = "fenics-nl developers"
copyright = "2026, fenics-nl developers"

extensions = [
    "myst_nb",  # Markdown pages (MyST) and the executed notebooks
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",  # the docstrings' Google style (Args:, Returns:)
    "sphinx.ext.mathjax",
]
# MathJax 3 served by the site itself, no CDN: the files of the pinned
# sphinx-mathjax-offline wheel (its folder name has hyphens: not importable as a module)
MATHJAX = Path(sysconfig.get_paths()["purelib"]) / "sphinx-mathjax-offline" / "static"
mathjax_path = "mathjax/tex-chtml.js"
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3  # [..](#which-method-when) links inside a page
nb_execution_mode = "off"  # docs/notebooks.py ran them, as a user would
exclude_patterns = ["_build", "_generated", "screenshots", "**.ipynb_checkpoints"]
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "show-inheritance": True}
napoleon_google_docstring = True
napoleon_numpy_docstring = False

html_theme = "furo"
html_title = "fenics-nl"
html_static_path = [str(MATHJAX)]  # copied into _static/

# The docstrings write `name` for code (as Markdown does) and |x| for absolute values and
# norms: the first is literal text, the second must not be read as an RST substitution.
default_role = "literal"


def _escape_bars(app, what, name, obj, options, lines):
    """|x| → \\|x\\| outside ``literal`` spans: a norm, not a substitution reference."""
    import re

    for i, line in enumerate(lines):
        parts = re.split(r"(``.*?``|`[^`]*`)", line)
        lines[i] = "".join(p if p.startswith("`") else p.replace("|", "\\|") for p in parts)


def _generate(app):
    """The pages' tables made from the code: the case format's keys (cases.md)."""
    from fenics_nl.case.spec import key_table

    out = Path(app.srcdir) / "_generated"
    out.mkdir(exist_ok=True)
    (out / "case_keys.md").write_text(key_table())


def setup(app):
    app.connect("builder-inited", _generate)
    app.connect("autodoc-process-docstring", _escape_bars)
