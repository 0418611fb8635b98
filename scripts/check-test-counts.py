#!/usr/bin/python3
"""Checks that the sanitizer stage of scripts/test.sh ran what the first stage ran.

Usage: check-test-counts.py FIRST_STAGE.xml SANITIZER_STAGE.xml   (ctest --output-junit files)

Every test that passed in the first stage must also have passed in the sanitizer stage, except
the CUDA ones (that build leaves CUDA out: compute-sanitizer checks its kernels on a GPU) and the
Python module's (an ASan-built module cannot load into an uninstrumented interpreter). A
stage that ran no test, or that skipped or lost tests the first stage ran, fails with their names.
Standard library only (Debian's /usr/bin/python3).
"""
import sys
import xml.etree.ElementTree as ET


def results(path):
    """name -> status ("run", "fail", "notrun", "disabled") of every test in a ctest JUnit file.

    GoogleTest's value-parameterized names end in "  # GetParam() = ...", which may print
    addresses that differ between builds: only the part before it names the test."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as e:
        sys.exit(f"check-test-counts: cannot read {path}: {e}")
    return {t.get("name").split("  # ")[0]: t.get("status") for t in root.iter("testcase")}


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__.strip().splitlines()[2])
    first, second = results(sys.argv[1]), results(sys.argv[2])
    expected = sorted(n for n, s in first.items()
                      if s == "run" and "cuda" not in n.lower() and not n.startswith("Python."))
    passed = {n for n, s in second.items() if s == "run"}
    missing = [n for n in expected if n not in passed]
    ran = len(passed)
    print(f"check-test-counts: first stage passed {len(expected)} tests that the sanitizer stage "
          f"must run (CUDA and Python ones left out); the sanitizer stage passed {ran} of {len(second)}")
    if ran == 0:
        sys.exit("check-test-counts: FAILED: the sanitizer stage ran no test")
    if missing:
        shown = "\n  ".join(f"{n} ({second.get(n, 'absent')})" for n in missing[:40])
        more = f"\n  ... and {len(missing) - 40} more" if len(missing) > 40 else ""
        sys.exit(f"check-test-counts: FAILED: {len(missing)} tests passed in the first stage but "
                 f"did not pass under the sanitizers:\n  {shown}{more}")


if __name__ == "__main__":
    main()
