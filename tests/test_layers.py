"""The package's import graph, read from the source with ast (every import, at module level or
inside a function): no module imports from a later stage, and no circle between modules. A stage
may use the stages before it; the order is the one a reader follows, foundations first."""

from __future__ import annotations

import ast

from conftest import ROOT

PACKAGE = ROOT / "generator" / "dyngen"
STAGES = (
    {"dyngen", "errors", "untrusted", "arguments", "options", "parameters", "atomic", "cache", "progress", "blas",
     "yaml_policy", "output_paths"},
    {"description"},  # the robot, its joint model and kinematics
    {"terms"},  # the torque terms: columns, ranges and C of every term
    {"catalogue"},
    {"derivation", "reduction"},
    {"emission"},
    {"generate", "runtime", "export"},
    {"validation"},
    {"excitation"},
    {"extraction"},  # consistent link parameters (its solver serves identify too)
    {"data"},  # recordings and their conditioning
    {"identification"},
    {"streaming"},  # least squares and the gap in blocks, per recording, in parallel
    {"diagnosis"},
    {"commands"},
    {"cli", "__main__"},
)
RANK = {name: k for k, names in enumerate(STAGES) for name in names}


def modules() -> dict:
    """module name -> path, for every module of the package."""
    out = {}
    for path in PACKAGE.rglob("*.py"):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return out


def imports(name: str, path, known: dict) -> set:
    """The package's modules that `name` imports (a name imported from a package: its module
    if it is one, else the package; not those under `if TYPE_CHECKING:`)."""
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):  # imports for type annotations only are not run
        if isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING":
            node.body = []
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.split(".")[0] == "dyngen"}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            elif node.module and node.module.split(".")[0] == "dyngen":
                target = node.module
            else:
                continue
            subs = {f"{target}.{a.name}" for a in node.names} & set(known)
            out |= subs if subs else {target}
    return {m for m in out if m in known and m != name}


def stage(module: str) -> int:
    parts = module.split(".")
    return RANK[parts[1] if len(parts) > 1 else parts[0]]


def graph() -> dict:
    known = modules()
    return {name: imports(name, path, known) for name, path in known.items()}


def test_every_module_has_a_stage():
    assert all(stage(m) is not None for m in modules())


def test_no_import_from_a_later_stage():
    # The package itself is the public facade: dyngen.load() loads the runtime when called.
    late = sorted(f"{a} -> {b}" for a, bs in graph().items() for b in bs if stage(b) > stage(a)
                  and not (a == "dyngen" and b == "dyngen.runtime"))
    assert not late, late


def test_no_circle():
    g = graph()
    # A package's __init__ gathering its own modules is no circle with them: drop those edges.
    g = {a: {b for b in bs if not (b.startswith(a + ".") and PACKAGE.joinpath(*a.split(".")[1:], "__init__.py").exists())}
         for a, bs in g.items()}
    state, circles = {}, []

    def visit(node, path):
        state[node] = "open"
        for nxt in sorted(g[node]):
            if state.get(nxt) == "open":
                circles.append(path[path.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt, path + [nxt])
        state[node] = "done"

    for node in sorted(g):
        if node not in state:
            visit(node, [node])
    assert not circles, circles
