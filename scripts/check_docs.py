#!/usr/bin/env python3
"""Checks the manual beyond what Sphinx checks (scripts/docs.sh runs both):
- README.md has at most 150 lines;
- every relative link in README.md, docs/, examples/ and formats/ Markdown resolves to a file (and
  a '#fragment' into a Markdown file to one of its headings);
- every repository path named in backticks in those files exists (e.g. `solver/body/exact_inertia.cpp`);
- every example folder's README.md and every formats/*.md is included by a page of the manual;
- every option each program's --help prints is in docs/reference/cli.md;
- no page speaks of development history ("issue <number>", "session"), and no tracked source file
  names an issue number.
Prints each finding as FILE:LINE: what; exit 1 if any. Usage: check_docs.py [--bin build/bin]"""
import argparse
import glob
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")
CODE_PATH = re.compile(r"`((?:reducer|solver|formats|inspect|tests|examples|scripts|benchmarks|python|docs|meshes)"
                       r"/[A-Za-z0-9_./-]+)`")
HISTORY = re.compile(r"\bissues? #?[0-9]+|\bsessions?\b|\bgit log\b", re.IGNORECASE)


def markdown_files():
    files = ["README.md"] + sorted(glob.glob("docs/**/*.md", recursive=True))
    files += sorted(glob.glob("examples/**/*.md", recursive=True)) + sorted(glob.glob("formats/*.md"))
    return [f for f in files if "/_generated/" not in f]


def slug(heading):
    """MyST's and GitHub's anchor of a heading: lower case, punctuation dropped, spaces to '-'."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


def anchors(path):
    """The heading anchors of a Markdown file, with those of the files it includes ({include})."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    found = {slug(m.group(1)) for m in re.finditer(r"^#+ (.*)$", text, re.MULTILINE)}
    for included in re.findall(r"^```\{include\} (\S+)", text, re.MULTILINE):
        found |= anchors(os.path.normpath(os.path.join(os.path.dirname(path), included)))
    return found


def check_links(path, lines, say):
    base = os.path.dirname(path)
    for n, line in enumerate(lines, 1):
        for target in LINK.findall(line):
            if re.match(r"^[a-z]+:", target) or target.startswith("#"):
                continue
            file_part, _, fragment = target.partition("#")
            resolved = os.path.normpath(os.path.join(base, file_part))
            if not os.path.exists(resolved):
                say(path, n, f"link to {target}: no file {resolved}")
            elif fragment and resolved.endswith(".md") and fragment not in anchors(resolved):
                say(path, n, f"link to {target}: no heading with the anchor #{fragment}")
        for named in CODE_PATH.findall(line):
            if any(c in named for c in "<>*") or named.endswith("/"):
                continue
            if not os.path.exists(named.rstrip(".")):
                say(path, n, f"`{named}`: no such file or folder")


def check_history(path, lines, say):
    for n, line in enumerate(lines, 1):
        m = HISTORY.search(line)
        if m:
            say(path, n, f"development history in the product: '{m.group(0)}'")


def check_sources(say):
    """No tracked source, script or build file names an issue number."""
    files = subprocess.run(["git", "ls-files"], capture_output=True, text=True).stdout.split()
    pattern = re.compile(r"\bissues? #?[0-9]+", re.IGNORECASE)
    for path in files:
        if not path.endswith((".cpp", ".h", ".py", ".sh", ".txt", ".yaml", ".geo", ".md")) or not os.path.isfile(path):
            continue
        with open(path, encoding="utf-8", errors="replace") as f:
            for n, line in enumerate(f, 1):
                if pattern.search(line) and path != "scripts/check_docs.py":
                    say(path, n, "names an issue number")


def check_reachable(say):
    pages = "\n".join(open(p, encoding="utf-8").read() for p in glob.glob("docs/**/*.md", recursive=True))
    for readme in sorted(glob.glob("examples/*/README.md")):
        if f"../../{readme}" not in pages:
            say(readme, 1, "not included by any page of docs/ (docs/examples/<case>.md)")
    for fmt in sorted(glob.glob("formats/*.md")):
        if f"../../{fmt}" not in pages:
            say(fmt, 1, "not included by any page of docs/reference/")
    examples = {os.path.basename(os.path.dirname(p)) for p in glob.glob("examples/*/run.sh")}
    examples |= {os.path.basename(os.path.dirname(p)) for p in glob.glob("examples/*/*.yaml")}
    for case in sorted(examples - {"common"}):
        if not os.path.exists(f"examples/{case}/README.md"):
            say(f"examples/{case}", 1, "an example without a README.md")


def check_cli(bin_dir, say):
    with open("docs/reference/cli.md", encoding="utf-8") as f:
        reference = f.read()
    for program in ("femb-reduce", "femb-solve", "femb-inspect"):
        text = subprocess.run([os.path.join(bin_dir, program), "--help"], capture_output=True, text=True).stdout
        for option in sorted(set(re.findall(r"(?<![\w-])(--[a-z][a-z-]*|-[a-z])\b", text))):
            if f"`{option}" not in reference and f" {option}`" not in reference and f"`{option} " not in reference:
                say("docs/reference/cli.md", 1, f"{program}'s option {option} is not in the reference")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"))
    args = parser.parse_args()
    os.chdir(ROOT)
    findings = []

    def say(path, line, what):
        findings.append(f"{path}:{line}: {what}")

    with open("README.md", encoding="utf-8") as f:
        n_readme = len(f.read().splitlines())
    if n_readme > 150:
        say("README.md", n_readme, f"{n_readme} lines; at most 150")
    for path in markdown_files():
        with open(path, encoding="utf-8") as f:
            lines = f.read().splitlines()
        check_links(path, lines, say)
        check_history(path, lines, say)
    check_reachable(say)
    check_sources(say)
    check_cli(os.path.abspath(args.bin), say)
    for line in findings:
        print(line)
    print(f"check_docs: {len(markdown_files())} Markdown files, {len(findings)} findings")
    sys.exit(1 if findings else 0)


if __name__ == "__main__":
    main()
