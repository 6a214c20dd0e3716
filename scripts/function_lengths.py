#!/usr/bin/python3
"""Lists the C++ functions longer than a limit and the source files longer than a limit; exits 1
when there is one not allowed by --allow.

How it counts: every tracked .cpp and .h (git ls-files). A function is a brace block opened at
namespace or class scope by a line that is not a namespace, class, struct, enum or union, counted
from the first line of its declaration (the lines after the previous ';', '{' or '}' line) to its
closing brace, both included; lambdas and local classes count as part of the function that holds
them. Comments and string literals are skipped when matching braces. A file counts all its lines.

usage: function_lengths.py [--max 120] [--file-max 700] [--allow NAME]...
  NAME: a function's name as it is declared (e.g. ExactGyroscopic, or Class::Method).
"""
import argparse
import re
import subprocess
import sys


def functions(path):
    lines = open(path, encoding="utf-8").read().split("\n")
    depth, start, stack, out = 0, None, [], []
    for i, line in enumerate(lines):
        code = re.sub(r"//.*", "", line)
        code = re.sub(r'"(\\.|[^"\\])*"', '""', code)
        code = re.sub(r"'(\\.|[^'\\])*'", "''", code)
        for ch in code:
            if ch == "{":
                kind = "other"
                if start is None:
                    if re.search(r"\bnamespace\b", code) or code.strip().startswith("extern"):
                        kind = "scope"
                    elif re.search(r"\b(class|struct|enum|union)\b", code) and not re.search(r"\)\s*(const)?\s*\{", code):
                        kind = "scope"
                    else:
                        kind = "function"
                        j = i
                        while j > 0 and lines[j - 1].strip() and not lines[j - 1].strip().endswith((";", "}", "{")) \
                                and not lines[j - 1].strip().startswith(("//", "#")):
                            j -= 1
                        start = (j, i, depth)
                stack.append(kind)
                depth += 1
            elif ch == "}":
                depth -= 1
                if stack:
                    stack.pop()
                if start is not None and depth == start[2]:
                    j = start[0]
                    head = " ".join(l.strip() for l in lines[j:start[1] + 1])
                    out.append((i - j + 1, j + 1, head))
                    start = None
    return out, len(lines)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--max", type=int, default=120)
    ap.add_argument("--file-max", type=int, default=700)
    ap.add_argument("--allow", action="append", default=[])
    a = ap.parse_args()
    files = subprocess.run(["git", "ls-files", "*.cpp", "*.h"], capture_output=True, text=True, check=True).stdout.split()
    bad = 0
    for f in files:
        fns, n = functions(f)
        if n > a.file_max:
            print(f"function_lengths: {f}: {n} lines (at most {a.file_max})")
            bad += 1
        for length, line, head in fns:
            if length <= a.max:
                continue
            allowed = any(re.search(r"\b" + re.escape(name) + r"\s*\(", head) for name in a.allow)
            print(f"function_lengths: {f}:{line}: {length} lines (at most {a.max}){' (allowed)' if allowed else ''}: "
                  f"{head[:100]}")
            bad += 0 if allowed else 1
    if bad == 0:
        print(f"function_lengths: every function of {len(files)} sources within {a.max} lines, every file within "
              f"{a.file_max}" + (" (but those allowed)" if a.allow else ""))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
