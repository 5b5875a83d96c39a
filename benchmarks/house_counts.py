"""The house's counts that issue 28 asks for, read from the source tree (no import of hystkit).

Run:  python benchmarks/house_counts.py [--src src/hystkit] [--list]

Prints: modules over 400 and over 600 lines; imports inside functions (what is imported when a
function runs, not when its module loads; ``if TYPE_CHECKING:`` blocks are not counted);
import cycles between modules (strongly connected components of more than one module, of the
module-level imports and of all imports); files under ``export/_families``; and uses of ``sys.meta_path`` and
``os._exit``. ``--list`` also names the modules behind each count.
"""

from __future__ import annotations

import argparse
import ast
from pathlib import Path

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

REPO = Path(__file__).resolve().parents[1]


def _module_name(path: Path, src: Path) -> str:
    parts = list(path.relative_to(src.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _is_type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _imports(tree: ast.AST, *, in_function: bool = False):
    """(import node, inside a function) for every import outside ``if TYPE_CHECKING``."""
    for node in ast.iter_child_nodes(tree):
        if isinstance(node, ast.If) and _is_type_checking(node):
            continue
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node, in_function
        inner = in_function or isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef,
                                                 ast.Lambda))
        yield from _imports(node, in_function=inner)


def _targets(node: ast.Import | ast.ImportFrom, module: str, is_package: bool,
             modules: dict) -> list[str]:
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names]
    if node.level:
        base = module.split(".")
        base = base[:len(base) - node.level + (1 if is_package else 0)]
        prefix = ".".join(base + ([node.module] if node.module else []))
    else:
        prefix = node.module or ""
    # `from p import x` imports the submodule p.x when there is one, else a name of p
    return [f"{prefix}.{alias.name}" if f"{prefix}.{alias.name}" in modules else prefix
            for alias in node.names]


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module."""
    names = sorted(graph)
    where = {name: i for i, name in enumerate(names)}
    edges = [(where[a], where[b]) for a in names for b in graph[a]]
    rows, cols = zip(*edges) if edges else ((), ())
    adjacency = coo_matrix((np.ones(len(edges)), (rows, cols)), shape=(len(names),) * 2)
    _, label = connected_components(adjacency, directed=True, connection="strong")
    groups = [[n for n, lab in zip(names, label) if lab == k] for k in set(label)]
    return sorted(g for g in groups if len(g) > 1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--src", type=Path, default=REPO / "src" / "hystkit")
    parser.add_argument("--list", action="store_true", help="name the modules behind each count")
    args = parser.parse_args()
    files = sorted(args.src.rglob("*.py"))
    modules = {_module_name(f, args.src): f for f in files}
    lines = {name: len(f.read_text(encoding="utf-8").splitlines()) for name, f in modules.items()}
    local: dict[str, int] = {}
    graph: dict[str, set[str]] = {name: set() for name in modules}  # module-level imports
    every: dict[str, set[str]] = {name: set() for name in modules}  # and those in functions
    text_hits: dict[str, list[str]] = {"sys.meta_path": [], "os._exit": []}
    for name, path in modules.items():
        source = path.read_text(encoding="utf-8")
        for needle, hits in text_hits.items():
            hits.extend([name] * source.count(needle))
        tree = ast.parse(source)
        for node, in_function in _imports(tree):
            if in_function:
                local[name] = local.get(name, 0) + 1
            for target in _targets(node, name, path.name == "__init__.py", modules):
                if target in modules and target != name:
                    every[name].add(target)
                    if not in_function:
                        graph[name].add(target)
    over_400 = sorted((n for n in lines if lines[n] > 400), key=lines.get, reverse=True)
    over_600 = [n for n in over_400 if lines[n] > 600]
    cycles, cycles_any = _cycles(graph), _cycles(every)
    families = args.src / "export" / "_families"
    rows = [
        ("modules", len(modules), []),
        ("modules > 600 lines", len(over_600), [f"{n} ({lines[n]})" for n in over_600]),
        ("modules > 400 lines", len(over_400), [f"{n} ({lines[n]})" for n in over_400]),
        ("imports inside functions", sum(local.values()),
         [f"{n} ({k})" for n, k in sorted(local.items(), key=lambda x: -x[1])]),
        ("import cycles between modules", len(cycles), [" <-> ".join(c) for c in cycles]),
        ("  counting imports in functions", len(cycles_any),
         [" <-> ".join(c) for c in cycles_any]),
        ("files in export/_families",
         len(list(families.glob("*.py"))) if families.exists() else 0, []),
        *((f"uses of {needle}", len(hits), sorted(set(hits))) for needle, hits in
          text_hits.items()),
    ]
    for label, count, names in rows:
        print(f"{label:<32}{count:>6}")
        if args.list:
            for item in names:
                print(f"    {item}")


if __name__ == "__main__":
    main()
