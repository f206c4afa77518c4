"""The type stubs (`fado/_fado.pyi`) describe the native module as it is.

`mypy.stubtest` is the thorough check (signatures, defaults, read-only properties, `final`);
the introspection tests below need nothing but the standard library and catch the commonest
drift (a name added or renamed on one side only) even where mypy is not installed.
"""

from __future__ import annotations

import ast
import inspect
import os
import subprocess
import sys
from pathlib import Path

import pytest

import fado
from fado import _fado

STUB = Path(fado.__file__).with_name("_fado.pyi")


def stub_tree() -> ast.Module:
    return ast.parse(STUB.read_text(encoding="utf-8"))


def stub_classes() -> dict[str, set[str]]:
    """Public members (methods, properties, annotated attributes) of each stubbed class."""
    classes = {}
    for node in stub_tree().body:
        if isinstance(node, ast.ClassDef):
            members = set()
            for item in node.body:
                if isinstance(item, ast.FunctionDef):
                    members.add(item.name)
                elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
                    members.add(item.target.id)
            classes[node.name] = {m for m in members if not m.startswith("_")}
    return classes


def test_package_ships_stub_and_marker() -> None:
    assert STUB.is_file()
    assert STUB.with_name("py.typed").is_file()


def test_stub_declares_exactly_the_module_names() -> None:
    declared = set()
    for node in stub_tree().body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            declared.add(node.name)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            declared.add(node.target.id)
    assert declared >= set(_fado.__all__)
    private = {name for name in declared if name.startswith("_") and name != "__version__"}
    assert declared - private == set(_fado.__all__)


def test_stub_classes_have_the_runtime_members() -> None:
    for name, members in stub_classes().items():
        runtime = getattr(_fado, name)
        public = {m for m in dir(runtime) if not m.startswith("_")}
        if issubclass(runtime, BaseException):
            public -= set(dir(Exception))
            # set on each raised instance, not on the class
            members -= {"field", "argument", "line", "column"}
        assert members == public, name


def test_output_fields_agree_everywhere() -> None:
    classes = stub_classes()
    outputs = set(fado.OUTPUT_NAMES)
    assert outputs == classes["StepResult"] - {"to_dict"}
    extras = {"to_dict", "keys", "to_pandas", "time", "ts", "dtype"}
    assert outputs == classes["EstimateResult"] - extras


def test_config_fields_agree_everywhere() -> None:
    fields = list(fado.EstimatorConfig.fields)
    props = stub_classes()["EstimatorConfig"] - {"replace", "to_dict", "paper_path", "fields"}
    assert set(fields) == props
    for node in stub_tree().body:
        if isinstance(node, ast.ClassDef) and node.name == "EstimatorConfig":
            for item in node.body:
                if isinstance(item, ast.FunctionDef) and item.name in ("__new__", "replace"):
                    assert [a.arg for a in item.args.kwonlyargs] == fields, item.name
    assert list(inspect.signature(fado.EstimatorConfig().replace).parameters) == fields


def test_stubtest(tmp_path: Path) -> None:
    pytest.importorskip("mypy")
    # From an empty directory: mypy takes modules in its working directory for the user's own,
    # and the installed package (with its stub) is the one to check.
    env = dict(os.environ, MYPYPATH="")
    proc = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "fado._fado"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=env,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
