"""Write ``clients/names.py``: every object name of the catalog as a typed attribute path.

    python tools/gen_names.py          # write clients/names.py
    python tools/gen_names.py --check  # exit 1 if clients/names.py is not what the catalog makes

An object name is a path: ``ch1.ax2.manual_increment_w``, ``ch1.wz[3].radius``,
``alarm_active[2].text``, ``gpCh[0].bahn_state.coord_r[1].v``. The generated module turns
each step into Python: a plain step is an attribute, a numbered step (``ch<c>``,
``ax<a>``, ``name[k]``) a call, so ``names.ch(1).ax(2).manual_increment_w`` is the string
``"ch1.ax2.manual_increment_w"`` and a misspelt step is a mypy error, found before the
program runs. Indices are not checked here (the service answers an unknown one with ADS
0x710); the shapes are the catalog's, taken from a machine with one of everything, so the
file does not depend on a machine's configuration.
"""

from __future__ import annotations

import argparse
import keyword
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

from cnc_objects.objects.catalog import CatalogSizes, ChannelLayout, MachineLayout, build_objects
from cnc_objects.objects.model import CncObject

REPO_ROOT = Path(__file__).resolve().parent.parent
TARGET = REPO_ROOT / "clients" / "names.py"

# One channel with one axis, one drive, one HLI axis, one tool, one zero offset group,
# one alarm history slot, two zero offset groups (G53, which has none, and G54): every
# template appears, whatever a machine configures.
_LAYOUT = MachineLayout((ChannelLayout(1, 1),), (1,), (1,))
# ch<c> / ax<a> steps and name[k] steps of a path
_NUMBERED_PREFIX = re.compile(r"^(ch|ax)(\d+)$")
_INDEXED = re.compile(r"^([A-Za-z_]\w*)\[(\d+)\]$")


def catalog_objects() -> list[CncObject]:
    """Every object of a machine with one of everything."""
    return build_objects(_LAYOUT, CatalogSizes(tool_entries=1, zero_offset_groups=2,
                                               alarm_history=1))


@dataclass(frozen=True)
class Step:
    """One step of an object name: ``word`` (an attribute), or ``word`` with an index
    (``ch1`` -> ``ch`` numbered without brackets, ``wz[1]`` -> ``wz`` with brackets)."""

    word: str
    numbered: bool = False  # a call: ch(c), ax(a), wz(k)
    brackets: bool = False  # the number is written name[k] (else name<k>)


def steps_of(name: str) -> list[Step]:
    """The steps of ``name``: ``ch1.wz[2].radius`` -> ch(), wz[](), radius."""
    steps: list[Step] = []
    for part in name.split("."):
        if (m := _INDEXED.match(part)) is not None:
            steps.append(Step(m.group(1), numbered=True, brackets=True))
        elif len(steps) < 2 and (m := _NUMBERED_PREFIX.match(part)) is not None:
            steps.append(Step(m.group(1), numbered=True))
        elif part.isidentifier():
            steps.append(Step(part))
        else:
            raise ValueError(f"object name {name!r}: step {part!r} is not a name")
    return steps


def attribute(word: str) -> str:
    """The Python attribute of a step: a keyword gets a trailing underscore (``class_``)."""
    return word + "_" if keyword.iskeyword(word) else word


@dataclass
class Node:
    """A namespace of the tree: its leaves (object names ending here) and its children."""

    path: tuple[str, ...]
    leaves: set[str] = field(default_factory=set)
    children: dict[Step, Node] = field(default_factory=dict)

    def child(self, step: Step) -> Node:
        """The child namespace of ``step``, made on first use."""
        if step not in self.children:
            self.children[step] = Node((*self.path, step.word))
        return self.children[step]

    @property
    def class_name(self) -> str:
        """``_ChWz`` for the path ch, wz; the root is ``_Root``."""
        if not self.path:
            return "_Root"
        return "_" + "".join(part[:1].upper() + part[1:]
                             for word in self.path for part in word.split("_"))


def build_tree(objects: list[CncObject]) -> Node:
    """The tree of every object name; a step that is both a leaf and a namespace fails."""
    root = Node(())
    for obj in objects:
        steps = steps_of(obj.name)
        node = root
        for step in steps[:-1]:
            node = node.child(step)
        last = steps[-1]
        if last.numbered:
            raise ValueError(f"object name {obj.name!r} ends in a number")
        node.leaves.add(last.word)
    _check_unambiguous(root)
    return root


def _check_unambiguous(node: Node) -> None:
    words = [s.word for s in node.children] + sorted(node.leaves)
    if len(words) != len(set(words)):
        raise ValueError(f"{'.'.join(node.path) or 'the root'}: a step is both an object "
                         f"and a namespace, or numbered and plain: {sorted(words)}")
    for child in node.children.values():
        _check_unambiguous(child)


def _classes(node: Node) -> list[str]:
    """The class of ``node`` and of every namespace below it, children first."""
    out: list[str] = []
    for child in sorted(node.children.values(), key=lambda n: n.path):
        out += _classes(child)
    if node.path:
        out.append(_class_text(node))
    return out


def _class_text(node: Node) -> str:
    where = ".".join(node.path)
    lines = [
        f"class {node.class_name}:",
        f'    """Objects below ``{where}``."""',
        "",
        '    __slots__ = ("_prefix",)',
        "",
        "    def __init__(self, prefix: str) -> None:",
        "        self._prefix = prefix",
    ]
    lines += _members(node, "self._prefix + ")
    return "\n".join(lines) + "\n"


def _members(node: Node, prefix: str, module_level: bool = False) -> list[str]:
    lines: list[str] = []
    for step, child in sorted(node.children.items(), key=lambda kv: kv[0].word):
        name = attribute(step.word)
        if module_level:
            if step.numbered:
                lines += ["", "",
                          f"def {name}(index: int) -> {child.class_name}:",
                          f'    """``{_numbered(step)}``."""',
                          f"    return {child.class_name}({_numbered_text(step)})"]
            else:
                lines += ["", "", f"{name}: Final = {child.class_name}(\"{step.word}.\")"]
            continue
        lines += [""]
        if step.numbered:
            lines += [f"    def {name}(self, index: int) -> {child.class_name}:",
                      f'        """``{_numbered(step)}``."""',
                      f"        return {child.class_name}({prefix}{_numbered_text(step)})"]
        else:
            lines += ["    @property",
                      f"    def {name}(self) -> {child.class_name}:",
                      f"        return {child.class_name}({prefix}\"{step.word}.\")"]
    for leaf in sorted(node.leaves):
        name = attribute(leaf)
        if module_level:
            lines += [f"{name}: Final = \"{leaf}\""]
        else:
            lines += ["", "    @property", f"    def {name}(self) -> str:",
                      f"        return {prefix}\"{leaf}\""]
    return lines


def _numbered(step: Step) -> str:
    return f"{step.word}[index]." if step.brackets else f"{step.word}<index>."


def _numbered_text(step: Step) -> str:
    return f'f"{step.word}[{{index}}]."' if step.brackets else f'f"{step.word}{{index}}."'


HEADER = '''"""Every object name of the catalog as a typed path (generated: do not edit).

Made by ``tools/gen_names.py`` from the object catalog (``make generate``); a test fails
when it is stale. A plain step is an attribute, a numbered one a call::

    from cnc_objects.clients import names

    names.ch(1).mc_active_state_r            # "ch1.mc_active_state_r"
    names.ch(1).ax(2).manual_increment_w     # "ch1.ax2.manual_increment_w"
    names.ch(1).wz(3).radius                 # "ch1.wz[3].radius"
    names.cnc_tick_counter_r                 # "cnc_tick_counter_r"

Each is the ``str`` the service knows, so it goes wherever a name goes
(``client.read(names.ch(1).mc_active_state_r)``); a misspelt step is a mypy error. A step
that is a Python keyword ends in ``_`` (``alarm_active(1).class_`` is ``...class``).
"""

from __future__ import annotations

from typing import Final

'''


def render(root: Node) -> str:
    """The whole module's text."""
    classes = _classes(root)
    if len({c.split(":", 1)[0] for c in classes}) != len(classes):
        raise ValueError("two namespaces make the same class name")
    module = _members(root, "", module_level=True)
    functions = [line for line in module if not line.endswith('"') or "Final" not in line]
    constants = [line for line in module if line not in functions]
    text = (HEADER + "\n" + "\n\n".join(classes) + "\n" + "\n".join(functions) + "\n\n\n"
            + "\n".join(constants) + "\n")
    return text


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true",
                        help="exit 1 if the file on disk differs from what would be written")
    args = parser.parse_args(argv)
    text = render(build_tree(catalog_objects()))
    if args.check:
        current = TARGET.read_text() if TARGET.exists() else ""
        if current != text:
            print(f"{TARGET.relative_to(REPO_ROOT)} is stale: run `make generate`",
                  file=sys.stderr)
            return 1
        return 0
    TARGET.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
