#!/usr/bin/env python3
"""The tests the docs name exist: every `Suite.Name`, `Suite.*` and
`...NameEnd` in docs/*.md and README.md is a test (or suite) of the GoogleTest
binaries, so a table's "test" column cannot point at a test that was renamed or
removed. Usage: check_test_names.py TEST_BINARY SOURCE_DIR [MORE_TEST_BINARIES...]"""
import glob
import re
import subprocess
import sys


def listed_tests(binary):
    out = subprocess.run([binary, "--gtest_list_tests"], capture_output=True, text=True, check=True).stdout
    tests, suite = set(), None
    for line in out.splitlines():
        if not line.strip() or line.startswith("Running main"):
            continue
        if not line.startswith(" "):
            suite = line.split()[0].rstrip(".")
        else:
            tests.add(suite + "." + line.split()[0])
    return tests


def plain(test):
    """Suite.Name without a parameterised prefix or suffix (Boards/Avrdude.X/0)."""
    suite, name = test.split(".", 1)
    return suite.split("/")[-1] + "." + name.split("/")[0]


def main():
    binaries, source = [sys.argv[1]] + sys.argv[3:], sys.argv[2]
    tests = {plain(t) for binary in binaries for t in listed_tests(binary)}
    suites = {t.split(".")[0] for t in tests}
    missing = []
    files = sorted(glob.glob(source + "/docs/*.md")) + [source + "/README.md"]
    for path in files:
        text = open(path, encoding="utf-8").read()
        for m in re.finditer(r"`([A-Z][A-Za-z0-9]+)\.(\*|[A-Z][A-Za-z0-9_]+)`", text):
            suite, name = m.group(1), m.group(2)
            found = suite in suites if name == "*" else suite + "." + name in tests
            if not found:
                missing.append(f"{path}: `{suite}.{name}` is not a test")
        for m in re.finditer(r"`\.\.\.([A-Z][A-Za-z0-9_]+)`", text):
            if not any(t.endswith("." + m.group(1)) for t in tests):
                missing.append(f"{path}: `...{m.group(1)}` ends no test's name")
    for line in missing:
        print(line)
    print(f"{len(missing)} of the docs' test names missing")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
