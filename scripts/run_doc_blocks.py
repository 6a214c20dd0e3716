#!/usr/bin/env python3
"""Runs every code block of a Markdown page as written: ```sh blocks with bash, ```python blocks
with /usr/bin/python3, in order, as one script (an `export` carries over to later blocks), from a
scratch folder that looks like the repository's root (build/ linked, examples/ copied without the
superelement files other runs write there, so that the blocks' outputs stay out of the source
tree and a test running beside it cannot hand it a half-written file). A block preceded by an
HTML comment that starts with "not run by the test" is skipped (the page says why). Exit 0 when
every block succeeds.

Usage: run_doc_blocks.py PAGE.md [--build DIR] [--keep]"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

FENCE = re.compile(r"^```(\w+)\s*$")


def blocks(text):
    """[(language, code, line)] of the page's fenced blocks, without the skipped ones."""
    found, lines, k = [], text.splitlines(), 0
    while k < len(lines):
        m = FENCE.match(lines[k])
        if not m:
            k += 1
            continue
        start, end = k, k + 1
        while end < len(lines) and lines[end].strip() != "```":
            end += 1
        previous = next((lines[j] for j in range(start - 1, -1, -1) if lines[j].strip()), "")
        skipped = previous.strip().startswith("<!-- not run by the test")
        if m.group(1) in ("sh", "python") and not skipped:
            found.append((m.group(1), "\n".join(lines[start + 1:end]), start + 1))
        k = end + 1
    return found


def script(page, found):
    """One bash script of the blocks, each announced by its line in the page."""
    parts = ["set -euo pipefail"]
    for language, code, line in found:
        parts.append(f"echo '--- {os.path.basename(page)}:{line} ({language})'")
        if language == "sh":
            parts.append(code)
        else:
            parts.append("/usr/bin/python3 - <<'FEMB_DOC_BLOCK'\n" + code + "\nFEMB_DOC_BLOCK")
    return "\n".join(parts) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("page")
    parser.add_argument("--build", default=None, help="the build folder (default: build/ beside scripts/)")
    parser.add_argument("--keep", action="store_true", help="keep the scratch folder")
    args = parser.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    build = os.path.abspath(args.build or os.path.join(root, "build"))
    with open(args.page) as f:
        found = blocks(f.read())
    if not found:
        sys.exit(f"{args.page}: no sh or python code blocks")
    work = tempfile.mkdtemp(prefix="femb_doc_")
    try:
        os.symlink(build, os.path.join(work, "build"))
        shutil.copytree(os.path.join(root, "examples"), os.path.join(work, "examples"),
                        ignore=shutil.ignore_patterns("out", "__pycache__", "*.h5", "*.tmp*"))
        os.symlink(os.path.join(root, "scripts"), os.path.join(work, "scripts"))
        result = subprocess.run(["bash", "-c", script(args.page, found)], cwd=work)
        print(f"run_doc_blocks: {len(found)} blocks of {args.page}: "
              f"{'all ran' if result.returncode == 0 else 'a block failed, exit %d' % result.returncode}")
        sys.exit(result.returncode)
    finally:
        if args.keep:
            print(f"run_doc_blocks: scratch folder {work}")
        else:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
