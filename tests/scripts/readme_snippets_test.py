#!/usr/bin/python3
"""The README's "Use it from C++" and "Use it from Python" snippets are copies of files that CI
builds and runs (examples/embed/CMakeLists.txt, python/example.py): each code block under those
headings must appear, line for line, in its file. Usage: readme_snippets_test.py SOURCE_DIR"""
import os
import re
import sys

SNIPPETS = {"Use it from C++": [("cmake", "examples/embed/CMakeLists.txt"),
                                ("cpp", "examples/embed/main.cpp")],
            "Use it from Python": [("python", "python/example.py")]}


def lines(text):
    """Lines without their indentation and trailing spaces: a snippet may be dedented."""
    return [line.strip() for line in text.splitlines()]


def contains(haystack, needle):
    return any(haystack[i:i + len(needle)] == needle for i in range(len(haystack) + 1))


def main():
    root = sys.argv[1]
    readme = open(os.path.join(root, "README.md")).read()
    failures = 0
    for heading, blocks in SNIPPETS.items():
        section = re.search(r"^#+ " + re.escape(heading) + r"\n(.*?)(?=^#+ |\Z)", readme, re.M | re.S)
        if not section:
            print(f"FAIL: README.md has no section '{heading}'")
            failures += 1
            continue
        for language, path in blocks:
            block = re.search(r"```" + language + r"\n(.*?)```", section.group(1), re.S)
            if not block:
                print(f"FAIL: '{heading}' has no ```{language} block")
                failures += 1
                continue
            source = open(os.path.join(root, path)).read()
            if not contains(lines(source), lines(block.group(1))):
                print(f"FAIL: the ```{language} block of '{heading}' is not a copy of part of {path}")
                failures += 1
            else:
                print(f"ok: '{heading}' ```{language}: {len(block.group(1).splitlines())} lines of {path}")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
