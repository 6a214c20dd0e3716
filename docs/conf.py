"""Sphinx configuration of femb's manual (docs/). Build: bash scripts/docs.sh (HTML into
build/docs/html, warnings as errors). The pages are Markdown (MyST); the file formats' pages include
formats/*.md, the examples' pages include examples/*/README.md, so each text has one source.

The command-line reference shows each program's --help as the build's binaries print it
(FEMB_BIN, default build/bin), and the Python reference is generated from the package's docstrings
(PYTHONPATH must reach build/python)."""
import os
import pathlib
import subprocess

project = "femb"
author = "the femb developers"
copyright = "the femb developers, GPL-3.0-or-later"
extensions = ["myst_parser", "sphinx.ext.autodoc"]
root_doc = "index"
exclude_patterns = ["_build", "_generated", "results/*.md"]
html_theme = "alabaster"
html_theme_options = {"page_width": "1100px", "sidebar_width": "230px"}
html_static_path = []
myst_enable_extensions = []
myst_heading_anchors = 3
autodoc_member_order = "bysource"
suppress_warnings = []

DOCS = pathlib.Path(__file__).resolve().parent
BIN = pathlib.Path(os.environ.get("FEMB_BIN", DOCS.parent / "build" / "bin"))


def write_help_texts(app):
    """docs/_generated/<program>.txt: each program's --help, included by reference/cli.md."""
    out = DOCS / "_generated"
    out.mkdir(exist_ok=True)
    for program in ("femb-reduce", "femb-solve", "femb-inspect"):
        exe = BIN / program
        if not exe.exists():
            raise RuntimeError(f"{exe}: not found; build femb first or set FEMB_BIN")
        text = subprocess.run([str(exe), "--help"], capture_output=True, text=True, check=True).stdout
        path = out / f"{program}.txt"
        if not path.exists() or path.read_text() != text:
            path.write_text(text)


def setup(app):
    app.connect("builder-inited", write_help_texts)
