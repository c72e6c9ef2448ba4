#!/usr/bin/env python3
"""Counts the test cases in catkin test_results folders (JUnit XML files).

Usage: summarize_tests.py RESULTS_DIR... [--sanitizer-reports DIR] [--slowest N]

Prints each failed case, and each sanitizer report found in DIR as a failure, the N slowest
result files (a gtest binary or a rostest, by the time their cases took), then
"N passed, N failed" on the last line; exits 1 if anything failed or no case ran at all.
"""
import argparse
import pathlib
import sys
import xml.etree.ElementTree as ET


def cases(results_dir):
    for path in sorted(pathlib.Path(results_dir).rglob("*.xml")):
        name = f"{pathlib.Path(results_dir).parent.name}/{path.name}"
        try:
            root = ET.parse(path).getroot()
        except ET.ParseError as error:
            yield name, "unreadable result file", str(error)
            continue
        for case in root.iter("testcase"):
            problems = case.findall("failure") + case.findall("error")
            case_name = f"{name}: {case.get('classname', '')}.{case.get('name', '')}"
            if problems:
                yield case_name, "failed", (problems[0].get("message") or problems[0].text or "").strip()
            elif case.find("skipped") is None and case.get("status") != "notrun":
                yield case_name, "passed", ""


def file_times(results_dir):
    """(name, seconds) of each result file: the sum of its cases' times."""
    for path in sorted(pathlib.Path(results_dir).rglob("*.xml")):
        try:
            root = ET.parse(path).getroot()
        except ET.ParseError:
            continue
        seconds = sum(float(case.get("time") or 0.0) for case in root.iter("testcase"))
        yield f"{pathlib.Path(results_dir).parent.name}/{path.name}", seconds


def sanitizer_reports(reports_dir):
    for path in sorted(pathlib.Path(reports_dir).glob("*")):
        yield f"sanitizer report {path}", "failed", path.read_text(errors="replace")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("results_dirs", nargs="*", default=["build/test_results"])
    parser.add_argument("--sanitizer-reports")
    parser.add_argument("--slowest", type=int, default=0)
    args = parser.parse_args()
    outcomes = [outcome for d in args.results_dirs for outcome in cases(d)]
    if args.sanitizer_reports:
        outcomes += list(sanitizer_reports(args.sanitizer_reports))
    passed = failed = 0
    for name, outcome, detail in outcomes:
        if outcome == "passed":
            passed += 1
        else:
            failed += 1
            print(f"FAILED {name}: {detail[:2000]}")
    if args.slowest:
        times = sorted((t for d in args.results_dirs for t in file_times(d)),
                       key=lambda item: -item[1])
        print(f"slowest {args.slowest}:")
        for name, seconds in times[:args.slowest]:
            print(f"  {seconds:8.1f} s  {name}")
    print(f"{passed} passed, {failed} failed")
    return 0 if failed == 0 and passed > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
