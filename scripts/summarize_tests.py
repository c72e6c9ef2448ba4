#!/usr/bin/env python3
"""Counts the test cases in a catkin test_results folder (JUnit XML files).

Prints each failed case, then "N passed, N failed" on the last line; exits 1 if any case
failed or no case ran at all.
"""
import pathlib
import sys
import xml.etree.ElementTree as ET


def cases(results_dir):
    for path in sorted(pathlib.Path(results_dir).rglob("*.xml")):
        try:
            root = ET.parse(path).getroot()
        except ET.ParseError as error:
            yield path.name, "unreadable result file", str(error)
            continue
        for case in root.iter("testcase"):
            problems = case.findall("failure") + case.findall("error")
            name = f"{path.name}: {case.get('classname', '')}.{case.get('name', '')}"
            if problems:
                yield name, "failed", (problems[0].get("message") or problems[0].text or "").strip()
            elif case.find("skipped") is None and case.get("status") != "notrun":
                yield name, "passed", ""


def main():
    results_dir = sys.argv[1] if len(sys.argv) > 1 else "build/test_results"
    passed = failed = 0
    for name, outcome, detail in cases(results_dir):
        if outcome == "passed":
            passed += 1
        else:
            failed += 1
            print(f"FAILED {name}: {detail[:500]}")
    print(f"{passed} passed, {failed} failed")
    return 0 if failed == 0 and passed > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
