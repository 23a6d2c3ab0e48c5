"""The package's import graph, read from the source with ast (every import, at module level or
inside a function): no module imports from a later stage, and no circle between modules. A stage
may use the stages before it; the order is the one a reader follows, foundations first. Inside
the diagnosis the same holds for its pipeline's stages (diagnosis/__init__.py), and no module of
the measured-data half is over MAX_LINES lines."""

from __future__ import annotations

import ast

from conftest import ROOT

PACKAGE = ROOT / "generator" / "dyngen"
STAGES = (
    {"dyngen", "errors", "untrusted", "arguments", "options", "parameters", "atomic", "cache", "progress", "blas",
     "yaml_policy", "output_paths", "forked"},
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
# The diagnosis's stages (diagnosis/__init__.py), its result's types and shared tools first.
DIAGNOSIS_STAGES = (
    {"record", "phases", "moments", "roles"},  # the result's types; 0. roles
    {"fit"},  # 1. fit (its candidates: dyngen.terms.library)
    {"forward_selection"},  # 2. select
    {"refine", "settle"},  # 3. settle
    {"joints", "reidentify", "choose"},  # 4. choose
    {"judge", "every_row"},  # 5. test (of long recordings: every row)
    {"findings", "findings_check", "stable", "across", "notes", "diagnose_options", "pipeline"},  # 6. report; the pipeline
    {"report_text", "updated_model", "residual_figures", "diagnosis_files", ""},  # written out; the package
)
DIAGNOSIS_RANK = {name: k for k, names in enumerate(DIAGNOSIS_STAGES) for name in names}
MEASURED_DATA = ("data", "diagnosis", "terms", "identification", "excitation", "streaming")
MEASURED_COMMANDS = ("diagnose", "identify", "identify_consistent", "excite", "recordings", "identify_least_squares", "survey",
                     "long_diagnosis")
MAX_LINES = 300


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


def diagnosis_stage(module: str) -> int:
    return DIAGNOSIS_RANK[module.removeprefix("dyngen.diagnosis").removeprefix(".")]


def test_diagnosis_stages_in_order():
    """No module of the diagnosis imports from a later stage of its pipeline."""
    inside = {a: {b for b in bs if b.startswith("dyngen.diagnosis")} for a, bs in graph().items()
              if a.startswith("dyngen.diagnosis")}
    assert set(map(diagnosis_stage, inside)) == set(range(len(DIAGNOSIS_STAGES)))  # every module has a stage
    late = sorted(f"{a} -> {b}" for a, bs in inside.items() for b in bs if diagnosis_stage(b) > diagnosis_stage(a))
    assert not late, late


def test_measured_data_modules_are_short():
    paths = [p for d in MEASURED_DATA for p in PACKAGE.joinpath(d).rglob("*.py")]
    paths += [PACKAGE / "commands" / f"{name}.py" for name in MEASURED_COMMANDS]
    assert len(paths) > 60 and all(p.exists() for p in paths)
    long = sorted(f"{p.relative_to(PACKAGE)}: {n}" for p in paths if (n := len(p.read_text().splitlines())) > MAX_LINES)
    assert not long, long
