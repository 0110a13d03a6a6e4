"""Write ``clients/blocking.py``: the blocking ``Client``, one real method per public
method of ``AsyncClient`` (its own and those of its mixins), with the same signature and
docstring, each running the async method to completion on the blocking transport.

Why generated: the methods must be declared (IDEs complete them, mypy checks a user's
call), yet written once (the async client is the one place the behaviour lives). The
signatures are taken from the source text with ``ast``, so defaults and annotations read
exactly as written. ``tests/clients/test_blocking_client.py`` fails when the file is not
what this script makes; rerun ``make generate`` after changing a public method.

    python tools/gen_blocking_client.py           # rewrite clients/blocking.py
    python tools/gen_blocking_client.py --check   # exit 1 when it is out of date
"""

from __future__ import annotations

import argparse
import ast
import builtins
import sys
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CLIENTS = ROOT / "clients"
TARGET = CLIENTS / "blocking.py"
#: The async client and its mixins, in method resolution order: (module file, class).
CLASSES = [
    ("client.py", "AsyncClient"),
    ("path_trace.py", "TraceOps"),
    ("channel_ops.py", "ChannelOps"),
    ("channel_ops.py", "ProgramOps"),
    ("alarm_ops.py", "AlarmOps"),
    ("machine_ops.py", "MachineOps"),
    ("tooling_ops.py", "ToolingOps"),
    ("manual_ops.py", "ManualOps"),
    ("spindle_ops.py", "SpindleOps"),
]
_ASYNC_ITERATORS = ("AsyncIterator", "AsyncGenerator")
_TYPING_NAMES = {"Any"}
_ABC_NAMES = {"Callable", "Iterable", "Iterator", "Mapping", "Sequence"}
_LINE_MAX = 99
_BASE_NAMES = ("BlockingClientBase", "iterate_blocking", "run_blocking")


@dataclass
class Method:
    """One public async method, as its source writes it."""

    name: str
    module: str  # the module (without .py) that defines it
    params: list[str]  # the parameters after self, as source text
    call: list[str]  # the arguments forwarding them
    returns: str  # the blocking method's return annotation
    iterates: bool  # an async generator: the blocking method returns an iterator
    doc: str | None
    names: set[str]  # names its annotations and defaults use


def _used_names(nodes: list[ast.AST]) -> set[str]:
    found: set[str] = set()
    for node in nodes:
        for sub in ast.walk(node):
            if isinstance(sub, ast.Name):
                found.add(sub.id)
    return found


def _method(module: str, source: str, fn: ast.AsyncFunctionDef) -> Method:
    args = fn.args
    if args.posonlyargs or args.vararg or args.kwarg:
        raise SystemExit(f"{module}.{fn.name}: only plain and keyword-only parameters "
                         "are supported by the generator")
    text: list[str] = []
    call: list[str] = []
    annotated: list[ast.AST] = []
    plain = args.args[1:]  # without self
    defaults = [None] * (len(plain) - len(args.defaults)) + list(args.defaults)
    for arg, default in zip(plain, defaults):
        text.append(_param(source, arg, default))
        call.append(arg.arg)
        annotated += [n for n in (arg.annotation, default) if n is not None]
    if args.kwonlyargs:
        text.append("*")
        for arg, kw_default in zip(args.kwonlyargs, args.kw_defaults):
            text.append(_param(source, arg, kw_default))
            call.append(f"{arg.arg}={arg.arg}")
            annotated += [n for n in (arg.annotation, kw_default) if n is not None]
    returns = ast.get_source_segment(source, fn.returns) if fn.returns is not None else "Any"
    assert returns is not None
    iterates = any(isinstance(n, ast.Yield | ast.YieldFrom) for n in ast.walk(fn))
    if iterates:
        kind, _, item = returns.partition("[")
        if kind not in _ASYNC_ITERATORS:
            raise SystemExit(f"{module}.{fn.name}: an async generator must be annotated "
                             "AsyncIterator[...] or AsyncGenerator[...]")
        returns = f"Iterator[{item.split(',')[0].removesuffix(']')}]"
    if fn.returns is not None:
        annotated.append(fn.returns)
    names = _used_names(annotated) - set(_ASYNC_ITERATORS)
    if iterates:
        names.add("Iterator")
    return Method(fn.name, module, text, call, returns, iterates,
                  ast.get_docstring(fn, clean=False), names)


def _param(source: str, arg: ast.arg, default: ast.expr | None) -> str:
    out = arg.arg
    if arg.annotation is not None:
        out += f": {ast.get_source_segment(source, arg.annotation)}"
        if default is not None:
            out += f" = {ast.get_source_segment(source, default)}"
    elif default is not None:
        out += f"={ast.get_source_segment(source, default)}"
    return out


def _module_names(module: str, tree: ast.Module) -> dict[str, tuple[str, str]]:
    """Names a module defines or imports at its top level: name -> (the module to import
    it from, its name there)."""
    found: dict[str, tuple[str, str]] = {}
    for node in tree.body:
        match node:
            case ast.ClassDef(name=name) | ast.FunctionDef(name=name):
                found[name] = (f".{module}", name)
            case ast.Assign(targets=targets):
                found |= {t.id: (f".{module}", t.id) for t in targets if isinstance(t, ast.Name)}
            case ast.AnnAssign(target=ast.Name(id=name)):
                found[name] = (f".{module}", name)
            case ast.ImportFrom(module=origin, names=aliases, level=level):
                source = "." * level + (origin or "")
                found |= {a.asname or a.name: (source, a.name) for a in aliases}
    return found


def collect() -> tuple[list[Method], dict[str, dict[str, tuple[str, str]]]]:
    """The public async methods in resolution order (the first definition of a name
    wins), and the names each module offers."""
    methods: dict[str, Method] = {}
    offered: dict[str, dict[str, tuple[str, str]]] = {}
    for file, cls_name in CLASSES:
        source = (CLIENTS / file).read_text(encoding="utf-8")
        tree = ast.parse(source)
        module = file.removesuffix(".py")
        offered[module] = _module_names(module, tree)
        cls = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == cls_name)
        for node in cls.body:
            if isinstance(node, ast.AsyncFunctionDef) and not node.name.startswith("_"):
                methods.setdefault(node.name, _method(module, source, node))
    return sorted(methods.values(), key=lambda m: m.name), offered


def _imports(methods: list[Method], offered: dict[str, dict[str, tuple[str, str]]]) -> list[str]:
    """Import lines for every name the generated signatures use, each from where its
    module has it."""
    wanted: dict[str, set[str]] = {".client": set(_BASE_NAMES)}
    abc: set[str] = set()
    typing: set[str] = set()
    for m in methods:
        for name in m.names:
            if name in _ABC_NAMES:
                abc.add(name)
            elif name in _TYPING_NAMES:
                typing.add(name)
            elif hasattr(builtins, name):
                continue
            elif name in offered[m.module]:
                origin, original = offered[m.module][name]
                alias = original if original == name else f"{original} as {name}"
                wanted.setdefault(origin, set()).add(alias)
            else:
                raise SystemExit(f"{m.module}.{m.name} uses {name}, which {m.module}.py "
                                 "does not define or import")
    typing.add("Any")
    standard = {m: wanted.pop(m) for m in list(wanted)
                if m.split(".")[0] in sys.stdlib_module_names}  # isort's first group
    if abc:
        standard["collections.abc"] = standard.get("collections.abc", set()) | abc
    standard["typing"] = standard.get("typing", set()) | typing
    lines = [_wrap(f"from {m} import ", sorted(standard[m]), "") for m in sorted(standard)]
    absolute = sorted(m for m in wanted if not m.startswith("."))
    relative = sorted(m for m in wanted if m.startswith("."))
    for group in (absolute, relative):
        if group:
            lines.append("")
        lines += [_wrap(f"from {m} import ", sorted(wanted[m]), "") for m in group]
    return lines


def _wrap(head: str, items: list[str], tail: str, indent: str = "") -> str:
    """``head`` + items + ``tail`` on one line when it fits, else one item a line."""
    line = f"{indent}{head}{', '.join(items)}{tail}"
    if len(line) <= _LINE_MAX:
        return line
    inner = indent + "    "
    body = "".join(f"{inner}{item},\n" for item in items)
    opener = head if head.endswith("(") else head + "("
    closer = tail if tail.startswith(")") else ")" + tail
    return f"{indent}{opener}\n{body}{indent}{closer}"


def _docstring(doc: str | None) -> list[str]:
    if not doc:
        return []
    body = doc.replace("\\", "\\\\").replace('"""', '\\"\\"\\"')
    return [f'        """{body}"""']


def render() -> str:
    """The text of clients/blocking.py."""
    methods, offered = collect()
    out = [
        "# Generated by tools/gen_blocking_client.py from AsyncClient and its mixins: do not",
        "# edit by hand; after changing a public method there, run `make generate`.",
        '"""The blocking client: ``Client`` has every public method of ``AsyncClient``, with',
        "the same signature, and runs it to completion on a blocking ZeroMQ socket (no event",
        'loop, no thread). Async generators (``subscribe``) become plain iterators."""',
        "",
        "from __future__ import annotations",
        "",
        *_imports(methods, offered),
        "",
        "",
        "class Client(BlockingClientBase):",
        '    """Blocking client: the same methods as ``AsyncClient``. Use with ``with``."""',
    ]
    for m in methods:
        params = ["self", *m.params]
        runner = "iterate_blocking" if m.iterates else "run_blocking"
        out += ["", _wrap(f"def {m.name}(", params, f") -> {m.returns}:", "    "),
                *_docstring(m.doc),
                _wrap(f"return {runner}(self._core.{m.name}(", m.call, "))", "        ")]
    return "\n".join(out) + "\n"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true",
                        help="exit 1 when clients/blocking.py is not what would be written")
    args = parser.parse_args()
    text = render()
    if args.check:
        if TARGET.read_text(encoding="utf-8") != text:
            print(f"{TARGET.relative_to(ROOT)} is out of date: run `make generate`",
                  file=sys.stderr)
            return 1
        return 0
    TARGET.write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
