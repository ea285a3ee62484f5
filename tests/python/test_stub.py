"""python/dpoint/__init__.pyi agrees with the module: the same public names, the same members of
each class, and the same parameters (names, kinds, defaults) for each function."""
import ast
import inspect
import os

import pytest

import dpoint

SOURCE_STUB = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python", "dpoint", "__init__.pyi")
BUILT_STUB = os.path.join(os.path.dirname(os.path.abspath(dpoint.__file__)), "__init__.pyi")


@pytest.fixture(scope="module")
def stub():
    with open(SOURCE_STUB, encoding="utf-8") as f:
        return ast.parse(f.read())


def stub_definitions(stub):
    return {node.name: node for node in stub.body if isinstance(node, (ast.FunctionDef, ast.ClassDef))}


def stub_names(stub):
    names = set(stub_definitions(stub))
    for node in stub.body:
        if isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets)
    return names


def test_the_built_package_carries_the_stub():
    with open(SOURCE_STUB, "rb") as a, open(BUILT_STUB, "rb") as b:
        assert a.read() == b.read()
    assert os.path.exists(os.path.join(os.path.dirname(BUILT_STUB), "py.typed"))


def test_every_public_name_is_in_the_stub(stub):
    missing = set(dpoint.__all__) - stub_names(stub)
    assert not missing


def test_every_function_and_class_of_the_stub_is_public(stub):
    public = {name for name in stub_definitions(stub) if not name.startswith("_")}
    assert public == set(dpoint.__all__) - {"__version__"}
    for name in public:
        assert hasattr(dpoint, name), name


def test_the_classes_have_the_stubs_members(stub):
    for name, node in stub_definitions(stub).items():
        if not isinstance(node, ast.ClassDef) or issubclass(getattr(dpoint, name), Exception):
            continue
        in_stub = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        in_stub |= {n.target.id for n in node.body if isinstance(n, ast.AnnAssign)}
        in_module = {m for m in dir(getattr(dpoint, name)) if not m.startswith("_")}
        assert {m for m in in_stub if not m.startswith("_")} == in_module, name
        for member in in_stub:
            assert hasattr(getattr(dpoint, name), member), (name, member)


def parameters_of_stub(node):
    """(name, kind, default) of a stub function's parameters, self dropped."""
    a = node.args
    result = []
    positional = a.posonlyargs + a.args
    defaults = [None] * (len(positional) - len(a.defaults)) + a.defaults
    for arg, default in zip(positional, defaults):
        result.append((arg.arg, "positional", ast.literal_eval(default) if default else inspect.Parameter.empty))
    if a.vararg:
        result.append((a.vararg.arg, "*args", inspect.Parameter.empty))
    for arg, default in zip(a.kwonlyargs, a.kw_defaults):
        result.append((arg.arg, "keyword", ast.literal_eval(default) if default else inspect.Parameter.empty))
    if a.kwarg:
        result.append((a.kwarg.arg, "**kwargs", inspect.Parameter.empty))
    return [p for p in result if p[0] != "self"]


KINDS = {
    inspect.Parameter.POSITIONAL_ONLY: "positional",
    inspect.Parameter.POSITIONAL_OR_KEYWORD: "positional",
    inspect.Parameter.VAR_POSITIONAL: "*args",
    inspect.Parameter.KEYWORD_ONLY: "keyword",
    inspect.Parameter.VAR_KEYWORD: "**kwargs",
}


def parameters_of(function):
    """The same of a function of the module: from its signature, or an extension function's docstring
    (pybind11 writes "name(a: T, *, b: T = 1) -> R" on its first line). read and write pass their
    keywords (**options) to the extension's function of the same name: its parameters are theirs."""
    try:
        signature = inspect.signature(function)
    except ValueError:
        line = function.__doc__.splitlines()[0]
        head = line[:line.rindex(" -> ")] if " -> " in line else line
        node = ast.parse("def " + head.replace("dpoint._dpoint.", "") + ": ...").body[0]
        return parameters_of_stub(node)
    passed_on = getattr(dpoint._dpoint, function.__name__, None)
    if "options" in signature.parameters and callable(passed_on):
        return parameters_of(passed_on)
    return [(p.name, KINDS[p.kind], p.default) for p in signature.parameters.values() if p.name != "self"]


def test_the_functions_have_the_stubs_parameters(stub):
    definitions = stub_definitions(stub)
    checked = []
    for name, node in definitions.items():
        if isinstance(node, ast.FunctionDef):
            assert parameters_of_stub(node) == parameters_of(getattr(dpoint, name)), name
            checked.append(name)
        elif isinstance(node, ast.ClassDef) and name in ("Renderer",):
            for method in node.body:
                if isinstance(method, ast.FunctionDef) and method.name in ("__init__", "render"):
                    assert parameters_of_stub(method) == parameters_of(getattr(dpoint.Renderer, method.name)), method.name
                    checked.append(f"Renderer.{method.name}")
    assert {"read", "write", "generate", "info", "render", "bench", "Renderer.render"} <= set(checked)
