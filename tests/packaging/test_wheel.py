"""The wheel installs one top-level package, cnc_objects, with every module of the
repository's package folders, and registers the pytest plugin."""

from __future__ import annotations

import configparser
import tomllib
import zipfile
from pathlib import Path

from tests.packaging.conftest import ROOT


def _pyproject() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())


def test_the_wheel_has_one_top_level_package(wheel: Path) -> None:
    version = _pyproject()["project"]["version"]
    with zipfile.ZipFile(wheel) as archive:
        top = {name.split("/")[0] for name in archive.namelist()}
    assert top == {"cnc_objects", f"cnc_objects-{version}.dist-info"}


def test_every_module_of_the_package_folders_is_in_the_wheel(wheel: Path) -> None:
    """A package left out of pyproject's explicit list would be missing from installs
    while every test in the checkout still passes."""
    package_dir = _pyproject()["tool"]["setuptools"]["package-dir"]
    expected = set()
    for package, folder in package_dir.items():
        for module in (ROOT / folder).rglob("*.py"):
            relative = module.relative_to(ROOT / folder)
            expected.add("/".join([*package.split("."), *relative.parts]))
    with zipfile.ZipFile(wheel) as archive:
        missing = expected - set(archive.namelist())
    assert "cnc_objects/testing/plugin.py" in expected
    assert not missing, sorted(missing)


def test_the_build_says_nothing_of_packages_it_was_not_told_of(
    wheel_build: tuple[Path, str]
) -> None:
    """Issue 36: `make run` on a clean clone printed setuptools' 40-line warning that the
    folder of cnc-web's pages is importable but absent from the ``packages`` list."""
    _, printed = wheel_build
    assert "absent from the `packages` configuration" not in printed, printed


def test_the_pytest_plugin_is_registered_by_entry_point(wheel: Path) -> None:
    with zipfile.ZipFile(wheel) as archive:
        [name] = [n for n in archive.namelist() if n.endswith(".dist-info/entry_points.txt")]
        text = archive.read(name).decode()
    entry_points = configparser.ConfigParser()
    entry_points.read_string(text)
    assert dict(entry_points["pytest11"]) == {"cnc_objects": "cnc_objects.testing"}
    assert entry_points["console_scripts"]["cnc-service"] == "cnc_objects.service.main:main"


def test_the_web_hmis_pages_and_command_are_in_the_wheel(wheel: Path) -> None:
    """cnc-web's pages are package data: an install without them serves 404s."""
    static = ROOT / "clients" / "web" / "static"
    expected = {f"cnc_objects/clients/web/static/{f.name}" for f in static.iterdir()}
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
        [entry] = [n for n in names if n.endswith(".dist-info/entry_points.txt")]
        text = archive.read(entry).decode()
    assert {"cnc_objects/clients/web/static/index.html",
            "cnc_objects/clients/web/static/main.js",
            "cnc_objects/clients/web/static/core.js"} <= expected <= names
    entry_points = configparser.ConfigParser()
    entry_points.read_string(text)
    assert entry_points["console_scripts"]["cnc-web"] == "cnc_objects.clients.web.cli:main"


def test_the_opc_foundation_nodesets_and_their_license_are_in_the_wheel(wheel: Path) -> None:
    """The OPC UA front end loads them at start: an install without them cannot serve."""
    folder = ROOT / "service" / "opcua" / "nodesets"
    expected = {f"cnc_objects/service/opcua/nodesets/{f.name}" for f in folder.iterdir()}
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
    assert "cnc_objects/service/opcua/nodesets/LICENSE" in expected
    assert "cnc_objects/service/opcua/nodesets/Opc.Ua.CNC.NodeSet.xml" in expected
    assert expected <= names
