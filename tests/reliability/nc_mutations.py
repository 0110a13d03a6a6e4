"""Mutated NC programs: the example programs and test data, changed the ways a careless
editor, a broken transfer or a hostile user change them; a hostile one also makes the
program write files named like the programs of the store (``file_writes``), which must
land in the output area and leave the store as it was.

Each mutation is a pure function of (text, random generator); ``mutate`` applies one to
three of them and names what it did, so that a failure names its program. Endless loops
are inserted on purpose (with and without motion): the test stops those with RESET after
a bounded time.
"""

from __future__ import annotations

import random
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from cnc_objects.protocol.constants import PROGRAM_MAX_BYTES
from tests.reliability import scale

ROOT = Path(__file__).resolve().parents[2]
#: Programs the mutations start from: every example of the docs and the syntax showcase.
SOURCE_GLOBS = ("docs/examples/*.nc", "docs/examples/cycles/*.nc", "docs/examples/hsc/*.nc",
                "tests/data/*.nc")
#: Files the examples call (cycles): uploaded next to the mutants, never mutated.
SUPPORT_GLOBS = ("docs/examples/cycles/*.ecy",)

NC_CHARACTERS = "GXYZFIJKRNMSTDLP$#%;()[]=<>+-*/.,:@\"'\\ \t0123456789"
HUGE_NUMBERS = [
    "9" * 400, "1" + "0" * 30, "-" + "9" * 40, "0." + "0" * 300 + "1", "1.7976931348623157E308",
    "4294967296", "-2147483649", "18446744073709551616", "-0", "0000000000000000000001",
]
TOKENS = [
    "$IF", "$ELSE", "$ENDIF", "$WHILE", "$ENDWHILE", "$FOR", "$ENDFOR", "$SWITCH", "$CASE",
    "$ENDSWITCH", "$GOTO [X]", "#VAR", "#ENDVAR", "#RT WHILE [TRUE]", "#RT ENDWHILE",
    "%L SUB", "LL SUB", "L missing.nc", "L CYCLE [NAME=none.ecy]", "G2 R0", "G3 I0 J0",
    "G41 D99", "F0", "F-1", "M30", "M17", "V.L.X = 1/0", "V.P.Y = SQRT[-1]",
    "#CONTOUR LOOKAHEAD LOG ON", "#MSG SAVE [\"%f\", 1]", "(", ")", "[", "]", "\x1a", "\x7f",
]
#: The store file every fuzz run keeps (``keep.nc``): the file writes aim at it.
KEEP = ("keep.nc", b"N10 G01 X1 F600\nN20 M30\n")
#: Names a mutant's ``#MSG SAVE`` writes to: store files, escapes, the kernel's own logs.
FILE_TARGETS = [KEEP[0], "drill.ecy", "mutant-00000.nc", "../keep.nc", "/tmp/x.nc",
                "errors-ch1.log", "dec01.sc", ".hidden", "msg.txt", "x" * 90]
FILE_SAVES = ['#MSG SAVE ["G01 X%d F9999", 777]', '#MSG SAVE EXCLUSIVE ["M30"]',
              '#MSG SAVE EXCLUSIVE ["%f", 2.5]', '#MSG SAVE ["' + "w" * 200 + '"]']
MOTION = ["G1 X10 F6000", "G1 X0 F6000", "G0 Y5", "G2 X0 Y0 I5 J0 F3000"]


@dataclass(frozen=True)
class Mutant:
    """A mutated program: its bytes, where it came from, what was done, and whether an
    endless loop was put in (its run is ended by RESET, not awaited)."""

    name: str
    data: bytes
    source: str
    changes: tuple[str, ...]
    endless: bool


def _lines(text: str) -> list[str]:
    return text.split("\n")


def flip_characters(text: str, rnd: random.Random) -> tuple[str, str]:
    """Replace 1..8 characters by NC-significant or arbitrary ones."""
    chars = list(text) or [" "]
    count = rnd.randint(1, 8)
    for _ in range(count):
        k = rnd.randrange(len(chars))
        chars[k] = rnd.choice(NC_CHARACTERS) if rnd.random() < 0.8 else chr(rnd.randint(1, 0x2FFF))
    return "".join(chars), f"flipped {count} characters"


def delete_lines(text: str, rnd: random.Random) -> tuple[str, str]:
    """Delete 1..5 lines."""
    lines = _lines(text)
    count = min(rnd.randint(1, 5), len(lines))
    for _ in range(count):
        del lines[rnd.randrange(len(lines))]
    return "\n".join(lines), f"deleted {count} lines"


def duplicate_lines(text: str, rnd: random.Random) -> tuple[str, str]:
    """Repeat a line 1..50 times in place."""
    lines = _lines(text)
    k = rnd.randrange(len(lines))
    times = rnd.randint(1, 50)
    lines[k:k + 1] = [lines[k]] * (times + 1)
    return "\n".join(lines), f"line {k + 1} repeated {times} times"


def swap_lines(text: str, rnd: random.Random) -> tuple[str, str]:
    """Swap two lines (an $ENDIF before its $IF, M30 before the motion)."""
    lines = _lines(text)
    a, b = rnd.randrange(len(lines)), rnd.randrange(len(lines))
    lines[a], lines[b] = lines[b], lines[a]
    return "\n".join(lines), f"lines {a + 1} and {b + 1} swapped"


def huge_numbers(text: str, rnd: random.Random) -> tuple[str, str]:
    """Replace 1..4 numbers by huge, tiny or out-of-range ones."""
    spans = [m.span() for m in re.finditer(r"\d+(\.\d*)?", text)]
    if not spans:
        return text + "\nG1 X" + rnd.choice(HUGE_NUMBERS) + " F600\n", "a huge move appended"
    chosen = sorted(rnd.sample(spans, min(len(spans), rnd.randint(1, 4))), reverse=True)
    for start, end in chosen:
        text = text[:start] + rnd.choice(HUGE_NUMBERS) + text[end:]
    return text, f"{len(chosen)} numbers made huge"


def deep_nesting(text: str, rnd: random.Random) -> tuple[str, str]:
    """Wrap a line in 50..400 levels of $IF or $WHILE (sometimes one end too few)."""
    lines = _lines(text)
    k = rnd.randrange(len(lines))
    depth = rnd.randint(50, 400)
    kind = rnd.choice(["if", "while", "for"])
    opener, closer = {
        "if": ("$IF 1 == 1", "$ENDIF"),
        "while": ("$WHILE V.L.NEST < 1", "V.L.NEST = 1\n$ENDWHILE"),
        "for": ("$FOR V.L.NEST = 0, 0, 1", "$ENDFOR"),
    }[kind]
    unbalanced = rnd.random() < 0.3
    body = [opener] * depth + [lines[k]] + [closer] * (depth - unbalanced)
    lines[k:k + 1] = body
    head = ["#VAR", "V.L.NEST = 0", "#ENDVAR"] if kind != "if" else []
    return "\n".join(head + lines), f"{depth} levels of ${kind.upper()}" + (
        ", one end missing" if unbalanced else "")


def endless_loop(text: str, rnd: random.Random) -> tuple[str, str]:
    """Put an endless loop at the start: $WHILE 1 with or without motion, or #RT WHILE."""
    lines = _lines(text)
    kind = rnd.choice(["motion", "idle", "variable", "rt"])
    loop = {
        "motion": ["$WHILE 1", rnd.choice(MOTION), rnd.choice(MOTION), "$ENDWHILE"],
        "idle": ["$WHILE 1", "$ENDWHILE"],
        "variable": ["#VAR", "V.L.LOOP = 0", "#ENDVAR", "$WHILE 1", "V.L.LOOP = V.L.LOOP + 1",
                     "$ENDWHILE"],
        "rt": ["#RT WHILE [TRUE]", rnd.choice(MOTION), "#RT ENDWHILE"],
    }[kind]
    return "\n".join(loop + lines), f"endless loop ({kind})"


def truncate(text: str, rnd: random.Random) -> tuple[str, str]:
    """Cut the file anywhere (a transfer that broke off)."""
    cut = rnd.randrange(len(text) + 1)
    return text[:cut], f"cut at byte {cut}"


def insert_tokens(text: str, rnd: random.Random) -> tuple[str, str]:
    """Insert 1..6 control-flow words, calls and oddities at random places."""
    count = rnd.randint(1, 6)
    for _ in range(count):
        k = rnd.randrange(len(text) + 1)
        text = text[:k] + rnd.choice([" ", "\n"]) + rnd.choice(TOKENS) + " " + text[k:]
    return text, f"{count} tokens inserted"


def long_line(text: str, rnd: random.Random) -> tuple[str, str]:
    """A line of 20 000..200 000 characters: a comment, a number, a string, a faulty
    word after a run of blanks, or a faulty word every three characters (the last two
    once stalled the syntax check: ``test_a_faulty_line_does_not_stall_the_cycle``)."""
    length = rnd.randint(20_000, 200_000)
    line = rnd.choice([";" + "x" * length, "G1 X" + "1" * length, "(" + "y" * length,
                       '#MSG ["' + "z" * length + '"]', "N1" + " " * length + "N1",
                       "N1 " * (length // 60)])
    lines = _lines(text)
    lines.insert(rnd.randrange(len(lines) + 1), line)
    return "\n".join(lines), f"a line of {len(line)} characters"


def file_writes(text: str, rnd: random.Random) -> tuple[str, str]:
    """Insert ``#FILE NAME [MSG=...]`` naming a store file (or an escape, or a log) and
    1..200 ``#MSG SAVE [EXCLUSIVE]`` lines at a random place."""
    lines = _lines(text)
    target = rnd.choice(FILE_TARGETS)
    count = rnd.choice([1, 2, rnd.randint(3, 200)])
    saves = [rnd.choice(FILE_SAVES) for _ in range(count)]
    lines[rnd.randrange(len(lines) + 1):0] = [f'#FILE NAME [MSG="{target}"]', *saves]
    return "\n".join(lines), f"{count} #MSG SAVE to {target[:20]}"


#: Words a line of many words is made of: each one bad in its own way (a word twice, an
#: unknown letter, an error inside brackets or in an expression, a G of a group given
#: before, a second program-flow M, a division by zero), or valid and distinct.
MANY_WORDS = [
    lambda k: "X1", lambda k: "Q5", lambda k: "M[1+*2]", lambda k: "G0 G1", lambda k: "M30",
    lambda k: "M[1/0]", lambda k: "V.L.X = 1/0", lambda k: "V.P.A = 1 +* 2",
    lambda k: f"M{100 + k}", lambda k: f"M[{k}+1-1]",
]


def many_words(text: str, rnd: random.Random) -> tuple[str, str]:
    """A line of thousands of words (up to ``Scale.long_line_words``), mostly of one
    kind, or one long expression, or a long comment after the words: the syntax check
    once took time quadratic in them and kept every error (issue 25)."""
    words = rnd.randint(1_000, max(1_000, scale.current().long_line_words))
    kind = rnd.randrange(len(MANY_WORDS) + 2)
    if kind == len(MANY_WORDS):  # one word whose value is a long expression
        line = "N1 G01 F100 X[1" + "+1-1" * (words // 2) + "]"
    elif kind == len(MANY_WORDS) + 1:  # a long comment behind the words
        line = "N1 G01 X1 F100 (" + "c" * (4 * words) + ")"
    else:
        make = MANY_WORDS[kind]
        mixed = rnd.random() < 0.3  # now and then other kinds in between
        line = "N1 G01 X1 F100 " + " ".join(
            (rnd.choice(MANY_WORDS) if mixed and rnd.random() < 0.2 else make)(k)
            for k in range(words))
    lines = _lines(text)
    lines.insert(rnd.randrange(len(lines) + 1), line)
    return "\n".join(lines), f"a line of {words} words ({len(line)} characters)"


MUTATIONS: list[Callable[[str, random.Random], tuple[str, str]]] = [
    flip_characters, flip_characters, delete_lines, duplicate_lines, swap_lines,
    huge_numbers, huge_numbers, deep_nesting, truncate, insert_tokens, insert_tokens, long_line,
]
FILE_WRITE_SHARE = 0.25  # of the mutants also write files (drawn apart: see ``mutate``)
#: Every MANY_WORDS_EVERY-th mutant also gets a line of many words, drawn from a generator
#: of its own (so the other mutants of a seed stay what they were).
MANY_WORDS_EVERY = 4
ENDLESS_SHARE = 0.08  # of the mutants get an endless loop (each costs the run timeout)
BINARY_SHARE = 0.05  # of the mutants get bytes that are not text


def sources() -> list[Path]:
    """The programs mutations start from, in a stable order."""
    return sorted(p for pattern in SOURCE_GLOBS for p in ROOT.glob(pattern))


def support_files() -> list[Path]:
    """Files the sources call (uploaded unchanged)."""
    return sorted(p for pattern in SUPPORT_GLOBS for p in ROOT.glob(pattern))


def mutate(index: int, path: Path, rnd: random.Random) -> Mutant:
    """Mutant number ``index`` of ``path``: one to three mutations, sometimes an endless
    loop, sometimes bytes that are not UTF-8."""
    text = path.read_text(encoding="utf-8", errors="replace")
    changes = []
    for _ in range(rnd.randint(1, 3)):
        text, change = rnd.choice(MUTATIONS)(text, rnd)
        changes.append(change)
    # drawn from a generator of their own, so the other mutations stay what they were
    writes = random.Random(f"{index} {path.name} {rnd.getstate()[1][0]}")
    if writes.random() < FILE_WRITE_SHARE:
        text, change = file_writes(text, writes)
        changes.append(change)
    if index % MANY_WORDS_EVERY == MANY_WORDS_EVERY - 1:
        text, change = many_words(text, random.Random(f"many words {index}"))
        changes.append(change)
    endless = rnd.random() < ENDLESS_SHARE
    if endless:
        text, change = endless_loop(text, rnd)
        changes.append(change)
    data = text.encode("utf-8", errors="surrogatepass")
    if rnd.random() < BINARY_SHARE:
        k = rnd.randrange(len(data) + 1)
        junk = bytes(rnd.randrange(256) for _ in range(rnd.randint(1, 64)))
        mixed = data[:k] + junk + data[k:]
        data = mixed
        changes.append(f"{len(junk)} raw bytes at {k}")
    if len(data) > PROGRAM_MAX_BYTES:  # what the store takes
        data = data[:PROGRAM_MAX_BYTES]
        changes.append(f"cut at the store's limit of {PROGRAM_MAX_BYTES} bytes")
    return Mutant(f"mutant-{index:05d}.nc", data, path.relative_to(ROOT).as_posix(),
                  tuple(changes), endless)
