#!/usr/bin/env python3
"""Keeps the docs true to the code: every topic, service and parameter that the node advertises,
subscribes to or reads has a row in docs/interface.md, and every row there names one it has;
every scene in config/scenes/ has a row in docs/scenes.md, and every row there names a file; the
README's interface table and scene list hold the same names; and every relative link of the README
and docs/ leads to a file, and to a heading where it names one.

The names are read from the node's sources (src/*.cpp, include/ball_physics_sim/*.h; the engine
has no ROS): advertise, advertiseService, subscribe, and every call whose name ends in Param or
param with a string literal for its first or second argument (param, getParam, and the node's
own checked readers such as positiveParam); the settings of cfg/*.cfg (gen.add), which
dynamic_reconfigure's server serves, have a table of their own; an interactive marker server
publishes its two topics under the namespace it is given. A documented name is the
backticked name in the first cell of a row of the first table under the section's heading (the
header row's cells have no backticks); `~` marks a private parameter.

Usage: test_docs.py [--junit-xml FILE]   (exits 1 on a failure)
"""
import argparse
import pathlib
import re
import sys
import time
import unittest
import xml.etree.ElementTree as ET

PACKAGE = pathlib.Path(__file__).resolve().parent.parent
NODE_SOURCES = sorted((PACKAGE / "src").glob("*.cpp")) + sorted(
    (PACKAGE / "include" / "ball_physics_sim").glob("*.h"))

# A string literal as a call's first argument, or as its second after a plain name (a handle).
_FIRST_LITERAL = r'\s*(?:<[^<>()]*(?:<[^<>()]*>)?[^<>()]*>)?\s*\(\s*(?:[\w.]+\s*,\s*)?"([^"]+)"'
PUBLISHED = re.compile(r"\badvertise" + _FIRST_LITERAL)
SERVICES = re.compile(r"\badvertiseService" + _FIRST_LITERAL)
SUBSCRIBED = re.compile(r"\bsubscribe" + _FIRST_LITERAL)
PARAMETERS = re.compile(r"\b\w*[pP]aram" + _FIRST_LITERAL)
# tf2_ros's broadcaster publishes /tf without an advertise of the node's own.
TF_BROADCASTER = re.compile(r"\bTransformBroadcaster\b")
# dynamic_reconfigure's server likewise offers ~set_parameters and publishes two topics.
RECONFIGURE_SERVER = re.compile(r"\bdynamic_reconfigure::Server\b")
RECONFIGURED = re.compile(r'\bgen\.add\(\s*"([^"]+)"')
# interactive_markers' server publishes NS/update and NS/update_full for the namespace it is given.
MARKER_SERVER = re.compile(r'\bInteractiveMarkerServer>?\s*\(\s*"([^"]+)"')


def node_code():
    return "\n".join(path.read_text() for path in NODE_SOURCES)


def names_in_code(pattern, code):
    return set(pattern.findall(code))


def section(markdown, heading):
    """The lines under the heading (any level, exact text), up to the next heading of its level
    or above."""
    lines = markdown.splitlines()
    for i, line in enumerate(lines):
        match = re.match(r"(#+)\s+(.*?)\s*$", line)
        if match and match.group(2) == heading:
            level = len(match.group(1))
            body = []
            for rest in lines[i + 1:]:
                other = re.match(r"(#+)\s", rest)
                if other and len(other.group(1)) <= level:
                    break
                body.append(rest)
            return body
    raise AssertionError(f"no section '{heading}'")


def table_names(markdown, heading):
    """The backticked name in the first cell of every row of a section's first table, without
    its `~`."""
    names = []
    in_table = False
    for line in section(markdown, heading):
        if not line.startswith("|"):
            if in_table:
                break
            continue
        in_table = True
        if re.match(r"\|\s*:?-", line):
            continue
        first_cell = line.split("|")[1]
        found = re.findall(r"`([^`]+)`", first_cell)
        if found:
            names.append(found[0].lstrip("~"))
    if not names:
        raise AssertionError(f"section '{heading}' has no table of names")
    return names


class DocsMatchCode(unittest.TestCase):
    longMessage = False  # the messages below say it all

    @classmethod
    def setUpClass(cls):
        cls.code = node_code()
        cls.interface = (PACKAGE / "docs" / "interface.md").read_text()
        cls.scenes_page = (PACKAGE / "docs" / "scenes.md").read_text()
        cls.readme = (PACKAGE / "README.md").read_text()
        cls.published = names_in_code(PUBLISHED, cls.code)
        if TF_BROADCASTER.search(cls.code):
            cls.published.add("/tf")
        for namespace in names_in_code(MARKER_SERVER, cls.code):
            cls.published |= {namespace + "/update", namespace + "/update_full"}
        cls.services = names_in_code(SERVICES, cls.code)
        if RECONFIGURE_SERVER.search(cls.code):
            cls.published |= {"parameter_descriptions", "parameter_updates"}
            cls.services.add("set_parameters")
        cls.reconfigured = names_in_code(RECONFIGURED, "\n".join(
            path.read_text() for path in sorted((PACKAGE / "cfg").glob("*.cfg"))))
        cls.subscribed = names_in_code(SUBSCRIBED, cls.code)
        cls.parameters = names_in_code(PARAMETERS, cls.code)
        cls.scenes = {path.stem for path in (PACKAGE / "config" / "scenes").glob("*.yaml")}

    def assertSameNames(self, documented, actual, what, page, source="the node's code"):
        problems = []
        twice = sorted({name for name in documented if documented.count(name) > 1})
        if twice:
            problems.append(f"listed twice: {twice}")
        if actual - set(documented):
            problems.append(f"missing: {sorted(actual - set(documented))}")
        if set(documented) - actual:
            problems.append(f"listed but not in {source}: {sorted(set(documented) - actual)}")
        self.assertFalse(problems, f"{page}, {what}: " + "; ".join(problems))

    def test_the_code_is_read(self):
        # A reader that found nothing would make every other check pass on an empty page.
        for what, names in [("published topics", self.published), ("services", self.services),
                            ("subscribed topics", self.subscribed),
                            ("parameters", self.parameters), ("scenes", self.scenes),
                            ("reconfigurable settings", self.reconfigured)]:
            self.assertTrue(names, f"no {what} found in the sources")

    def test_published_topics(self):
        self.assertSameNames(table_names(self.interface, "Topics published"), self.published,
                             "published topics", "docs/interface.md")

    def test_subscribed_topics(self):
        self.assertSameNames(table_names(self.interface, "Topics subscribed"), self.subscribed,
                             "subscribed topics", "docs/interface.md")

    def test_services(self):
        self.assertSameNames(table_names(self.interface, "Services"), self.services, "services",
                             "docs/interface.md")

    def test_parameters(self):
        self.assertSameNames(table_names(self.interface, "Parameters"), self.parameters,
                             "parameters", "docs/interface.md")

    def test_reconfigurable_settings(self):
        self.assertSameNames(table_names(self.interface, "Dynamic reconfigure"), self.reconfigured,
                             "reconfigurable settings", "docs/interface.md", "cfg/*.cfg")

    def test_scenes(self):
        self.assertSameNames(table_names(self.scenes_page, "Shipped scenes"), self.scenes,
                             "scenes", "docs/scenes.md", "config/scenes/")

    def test_readme_interface_table(self):
        self.assertSameNames(table_names(self.readme, "ROS interface"),
                             self.published | self.subscribed | self.services,
                             "topics and services", "README.md")

    def test_readme_scenes(self):
        self.assertSameNames(table_names(self.readme, "Scenes"), self.scenes, "scenes",
                             "README.md", "config/scenes/")


def anchors(markdown):
    """The anchors GitHub makes of a page's headings: lower case, punctuation dropped, spaces
    to hyphens."""
    return {re.sub(r"[^\w\- ]", "", match.group(1).strip().lower()).replace(" ", "-")
            for match in re.finditer(r"^#+\s+(.*)$", markdown, re.M)}


class LinksResolve(unittest.TestCase):
    longMessage = False  # the message below says it all

    def test_relative_links_point_at_files_and_headings_that_exist(self):
        broken = []
        for page in [PACKAGE / "README.md"] + sorted((PACKAGE / "docs").glob("*.md")):
            text = page.read_text()
            for target in re.findall(r"\]\(([^)\s]+)\)", text):
                if re.match(r"[a-z]+:", target):
                    continue
                path, _, anchor = target.partition("#")
                linked = (page.parent / path).resolve() if path else page
                if not linked.exists():
                    broken.append(f"{page.name}: {target}")
                elif anchor and linked.suffix == ".md" and anchor not in anchors(
                        linked.read_text()):
                    broken.append(f"{page.name}: {target} (no such heading)")
        self.assertFalse(broken, f"broken links: {broken}")


class _Recorder(unittest.TextTestResult):
    """A text result that also keeps each case's outcome and time for the JUnit file."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.outcomes = []

    def startTest(self, test):
        self._started = time.monotonic()
        super().startTest(test)

    def _record(self, test, kind, detail=""):
        # A failing setUpClass is reported for a stand-in, which was never started.
        started = getattr(self, "_started", time.monotonic())
        self.outcomes.append((test, kind, detail, time.monotonic() - started))

    def addSuccess(self, test):
        super().addSuccess(test)
        self._record(test, None)

    def addFailure(self, test, err):
        super().addFailure(test, err)
        self._record(test, "failure", self._exc_info_to_string(err, test))

    def addError(self, test, err):
        super().addError(test, err)
        self._record(test, "error", self._exc_info_to_string(err, test))


def write_junit(outcomes, path):
    suite = ET.Element("testsuite", name="test_docs", tests=str(len(outcomes)),
                       failures=str(sum(kind == "failure" for _, kind, _, _ in outcomes)),
                       errors=str(sum(kind == "error" for _, kind, _, _ in outcomes)))
    for test, kind, detail, seconds in outcomes:
        # A failing setUpClass is reported for a stand-in that is no TestCase.
        owner = type(test).__name__ if isinstance(test, unittest.TestCase) else "setUpClass"
        case = ET.SubElement(suite, "testcase", classname=f"test_docs.{owner}",
                             name=getattr(test, "_testMethodName", str(test)),
                             time=f"{seconds:.3f}")
        if kind:
            problem = ET.SubElement(case, kind, message=detail.strip().splitlines()[-1])
            problem.text = detail
    path.parent.mkdir(parents=True, exist_ok=True)
    ET.ElementTree(suite).write(path, encoding="utf-8", xml_declaration=True)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--junit-xml", type=pathlib.Path)
    args = parser.parse_args()
    tests = unittest.TestSuite(unittest.defaultTestLoader.loadTestsFromTestCase(case)
                               for case in (DocsMatchCode, LinksResolve))
    result = unittest.TextTestRunner(resultclass=_Recorder, verbosity=2).run(tests)
    if args.junit_xml:
        write_junit(result.outcomes, args.junit_xml)
    return 0 if result.wasSuccessful() else 1


if __name__ == "__main__":
    sys.exit(main())
