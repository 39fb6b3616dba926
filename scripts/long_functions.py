#!/usr/bin/env python3
"""Lists the functions in src/ longer than a limit (default 80 lines).

usage: scripts/long_functions.py [LIMIT] [--check]

A function is a definition whose body opens at the end of a line and whose
closing brace is the first later line with the same indentation (Google
style, as clang-format writes it): namespace-level functions, methods and
lambdas in headers and sources. A long function passes when the comment just
above its signature says why it is long (it contains "long" or "lines").
With --check the exit status is 1 if one does not.
"""
import os
import re
import sys

SIGNATURE_END = re.compile(r"\)\s*(const)?\s*(override)?\s*(noexcept)?\s*(->\s*[\w:<>, ]+)?\s*\{\s*$")
CONTROL = re.compile(r"^\s*(if|for|while|switch|catch|else|do)\b|^\s*\}\s*(else|catch)\b")


def functions(path):
    lines = open(path, encoding="utf-8").read().split("\n")
    for i, line in enumerate(lines):
        if not SIGNATURE_END.search(line) or CONTROL.search(line):
            continue
        if "=" in line.split("(")[0] and "operator" not in line:
            continue  # a lambda assigned to a variable is counted inside its function
        indent = len(line) - len(line.lstrip())
        # The signature may start on earlier lines.
        start = i
        while start > 0 and lines[start - 1].strip() and not lines[start - 1].strip().endswith((";", "}", "{")) \
                and not lines[start - 1].lstrip().startswith(("//", "#")):
            start -= 1
        end = i + 1
        while end < len(lines):
            l = lines[end]
            if l.strip() and len(l) - len(l.lstrip()) == indent and l.lstrip().startswith("}"):
                break
            if l.strip() and len(l) - len(l.lstrip()) < indent:
                end = None
                break
            end += 1
        if end is None or end >= len(lines):
            continue
        comment = []
        k = start - 1
        while k >= 0 and lines[k].lstrip().startswith("//"):
            comment.append(lines[k])
            k -= 1
        yield lines[start].strip(), start + 1, end - start + 1, " ".join(comment)


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    limit = int(args[0]) if args else 80
    check = "--check" in sys.argv
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")
    failures = 0
    for dirpath, _, names in sorted(os.walk(root)):
        for name in sorted(names):
            if not name.endswith((".cc", ".h")) or name.endswith("_test.cc"):
                continue
            path = os.path.join(dirpath, name)
            for sig, line, length, comment in functions(path):
                if length <= limit:
                    continue
                why = bool(re.search(r"\blong\b|\blines\b", comment))
                failures += 0 if why else 1
                rel = os.path.relpath(path, os.path.join(root, ".."))
                print(f"{rel}:{line}: {length} lines{' (commented)' if why else ''}: {sig[:70]}")
    if check and failures:
        print(f"{failures} function(s) over {limit} lines without a comment saying why", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
