"""The README's tour as data: the ``$ `` commands of its shell blocks, each with the output
the README shows under it, and a matcher that decides whether a real output is that one.

What the README shows is what a user sees, with three allowances a reader expects:

- ``...`` on a line of its own stands for any number of lines (a long table cut short);
- ``...`` inside a line stands for any text (a timestamp, a path);
- a decimal number may differ by up to five units in its last digit: with the realtime
  clock of `make run`, a run time includes the few 1 ms cycles the decoder needs to
  deliver the first block, and those vary with the machine's load;
- a duration in seconds (a decimal number followed by `` s``) may also come later, by
  up to ``LATE_DURATION_S``: on a loaded machine (CI runs the suite beside other jobs)
  the decoder of a syntax check can take 8 ms of the realtime clock where a quiet one
  takes 2. Load only delays, so a duration never comes earlier than the five units.

Runs of white space compare equal (tables piped through ``cnc`` are tab-separated).
"""

from __future__ import annotations

import contextlib
import fcntl
import re
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

ELLIPSIS = "..."
TOLERANCE_UNITS = 5.5  # of a decimal number's last digit (see above)
LATE_DURATION_S = 0.025  # how much later a realtime duration may come under load
# Commands a test cannot run as a user types them: a terminal UI, a broker in the
# background, containers. Their own tests cover them.
NOT_RUN = ("cnc-hmi", "mosquitto", "cnc-mqtt", "docker")
README_ENDPOINT = "tcp://127.0.0.1:5555"
README_WEB_PORT = 8080  # cnc-web beside the service, as `make run` starts it
README_AMS_NET_ID, README_ADS_HOST = "127.0.0.1.1.1", "127.0.0.1"  # what `make run` serves
README_OPCUA_URL = "opc.tcp://127.0.0.1:4840"  # where `make run` serves OPC UA


@contextlib.contextmanager
def readme_web_port() -> Iterator[None]:
    """Hold README_WEB_PORT for one test at a time: the tests that serve cnc-web where
    `make run` puts it run in separate pytest-xdist workers, and two of them at once
    would find the port taken (a file lock, as the workers are processes)."""
    path = Path(tempfile.gettempdir()) / f"cnc-objects-web-{README_WEB_PORT}.lock"
    with path.open("w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


_COMMENT = re.compile(r"\s+#\s.*$")
_NUMBER = re.compile(r"-?\d+(?:\.\d+)?")
_DURATION = re.compile(r"-?\d+\.\d+(?= s\b)")


@dataclass(frozen=True)
class TourStep:
    """One ``$ command`` of the README and the lines shown under it."""

    section: str
    command: str
    expected: tuple[str, ...]


#: A section of the tour that runs on another machine than `make run`'s default: its
#: own test (``machine_section``) plays it on that machine, the tour leaves it out.
FIVE_AXIS_SECTION = "\n## Five axes"
#: The OPC UA section: its own test plays it on a service serving OPC UA (the tour's
#: services leave OPC UA off), the tour leaves it out.
OPCUA_SECTION = "\n## OPC UA"
OWN_SECTIONS = (FIVE_AXIS_SECTION, OPCUA_SECTION)


def tour_text(readme: Path) -> str:
    """The README from the tour's first section up to "## What runs", without the
    sections played on their own (``OWN_SECTIONS``)."""
    text = readme.read_text()
    tour = text[text.index("\n## 1. "):text.index("\n## What runs")]
    for title in OWN_SECTIONS:
        start = tour.find(title)
        if start >= 0:
            end = tour.find("\n## ", start + 1)
            tour = tour[:start] + (tour[end:] if end >= 0 else "")
    return tour


def section_text(readme: Path, title: str) -> str:
    """The README section starting with ``title``, up to the next section."""
    text = readme.read_text()
    start = text.index(title)
    end = text.find("\n## ", start + 1)
    return text[start:end]


def machine_section(readme: Path, title: str = FIVE_AXIS_SECTION) -> list[TourStep]:
    """The ``$ `` commands of the README section starting with ``title`` (a section
    the tour leaves out, played on its own machine)."""
    return _shell_steps(section_text(readme, title), ())


def _blocks(text: str, language: str) -> list[tuple[str, list[str]]]:
    """(section title, lines) of every fenced block of ``language``."""
    blocks, section, inside, lines = [], "", False, []
    for line in text.splitlines():
        if not inside and line.startswith("## "):
            section = line[3:]
        if line.startswith("```"):
            if inside:
                blocks.append((section, lines))
                inside, lines = False, []
            elif line[3:].strip() == language:
                inside = True
            continue
        if inside:
            lines.append(line)
    return blocks


def _shell_steps(text: str, not_run: tuple[str, ...]) -> list[TourStep]:
    """Every ``$ `` command of the shell blocks of ``text`` with none of ``not_run``."""
    steps = []
    for section, lines in _blocks(text, "sh"):
        command, expected = None, []
        for line in [*lines, "$ "]:
            if line.startswith("$ "):
                if command and not any(word in command for word in not_run):
                    steps.append(TourStep(section, command, tuple(expected)))
                command, expected = _COMMENT.sub("", line[2:]).strip(), []
            else:
                expected.append(line)
    return steps


def tour_steps(readme: Path) -> list[TourStep]:
    """Every ``$ `` command of the tour's shell blocks that a test can run, in order."""
    return _shell_steps(tour_text(readme), NOT_RUN)


#: The MQTT step's commands the ordered tour plays itself (``tour_items``): a broker of
#: the test's own instead of ``mosquitto``, and its client instead of the Mosquitto tools.
BROKER_WORDS = ("mosquitto ", "cnc-mqtt", "mosquitto_sub", "mosquitto_pub")
NOT_RUN_IN_ORDER = ("cnc-hmi", "docker")


@dataclass(frozen=True)
class PythonStep:
    """A Python example of the tour and the output the README shows after it."""

    section: str
    code: str
    expected: tuple[str, ...]


def tour_items(readme: Path) -> list[TourStep | PythonStep]:
    """Every shell command (the MQTT step's included) and every Python example of the
    tour, in the order the README shows them: what a reader types, one after another."""
    items: list[TourStep | PythonStep] = []
    section, block, lines, pending = "", None, [], None
    for line in tour_text(readme).splitlines():
        if block is None and line.startswith("## "):
            section = line[3:]
        if line.startswith("```"):
            if block is None:
                block = line[3:].strip()
                continue
            if block == "sh":
                command, expected = None, []
                for entry in [*lines, "$ "]:
                    if entry.startswith("$ "):
                        if command and not any(w in command for w in NOT_RUN_IN_ORDER):
                            items.append(TourStep(section, command, tuple(expected)))
                        command, expected = _COMMENT.sub("", entry[2:]).strip(), []
                    else:
                        expected.append(entry)
            elif block == "python":
                pending = PythonStep(section, "\n".join(lines) + "\n", ())
            elif block == "text" and pending is not None:
                items.append(PythonStep(pending.section, pending.code, tuple(lines)))
                pending = None
            block, lines = None, []
            continue
        if block is not None:
            lines.append(line)
    return items


def python_examples(readme: Path, title: str | None = None
                    ) -> list[tuple[str, tuple[str, ...]]]:
    """Each Python example of the tour (of the section ``title`` when given) and the
    output shown in the ``text`` block after it."""
    text = tour_text(readme) if title is None else section_text(readme, title)
    examples = []
    for part in text.split("```python\n")[1:]:
        code, _, rest = part.partition("\n```\n")
        shown = rest.split("```text\n", 1)[1].split("\n```", 1)[0]
        examples.append((code + "\n", tuple(shown.splitlines())))
    return examples


def _normal(line: str) -> str:
    return " ".join(line.split())


def _line_matches(expected: str, actual: str) -> bool:
    expected, actual = _normal(expected), _normal(actual)
    numbers = _NUMBER.findall(expected.replace(ELLIPSIS, " "))
    durations = {m.start() for m in _DURATION.finditer(expected.replace(ELLIPSIS, " "))}
    starts = [m.start() for m in _NUMBER.finditer(expected.replace(ELLIPSIS, " "))]
    pattern = ""
    for k, part in enumerate(expected.split(ELLIPSIS)):
        if k:
            pattern += ".*?"
        last = 0
        for m in _NUMBER.finditer(part):
            pattern += re.escape(part[last:m.start()]) + r"(-?\d+(?:\.\d+)?)"
            last = m.end()
        pattern += re.escape(part[last:])
    found = re.fullmatch(pattern, actual)
    if found is None:
        return False
    for start, want, got in zip(starts, numbers, found.groups()):
        if "." not in want:
            if want != got:
                return False
            continue
        unit = 10 ** -len(want.split(".")[1])
        late_s = LATE_DURATION_S if start in durations else 0.0
        if not -unit * TOLERANCE_UNITS <= float(got) - float(want) <= unit * TOLERANCE_UNITS + late_s:
            return False
    return True


def output_matches(expected: tuple[str, ...], actual: list[str]) -> bool:
    """Whether ``actual`` lines are what the README shows (see the module docstring)."""
    expected = tuple(e for e in expected if e.strip())
    actual = [a for a in actual if a.strip()]
    if not expected:
        return not actual
    head, rest = expected[0], expected[1:]
    if head.strip() == ELLIPSIS:
        return any(output_matches(rest, actual[k:]) for k in range(len(actual) + 1))
    return bool(actual) and _line_matches(head, actual[0]) and output_matches(rest, actual[1:])
