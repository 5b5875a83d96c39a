"""The API reference's package pages, written from the packages' ``__all__`` at build time.

Before Sphinx lists the source files (``config-inited``), so that autosummary finds its
directives in them, this writes
``reference/api/<package>.rst`` for ``hystkit`` and every public subpackage with an
``__all__`` (no part of its name starting with ``_``; the set ``tests/docs/test_numpydoc.py``
checks). Each page has the package's docstring and an autosummary table of its classes and of
its functions, whose stub pages autosummary then generates from ``_templates/autosummary``.
A class or function exported by several packages is documented once, under its home: the
deepest exporting package its defining module lies in (``hystkit.io.Recording``, not
``hystkit.Recording``); the other packages list it with a link there. The folder is generated
and ignored by git; nothing in it is written by hand.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
from pathlib import Path

from docutils import nodes
from sphinx.application import Sphinx
from sphinx.environment import BuildEnvironment
from sphinx.ext import autosummary
from sphinx.util.nodes import get_node_source

FOLDER = Path("reference") / "api"
MAX_VALUE_CHARS = 120  # a constant's value is shown when its repr is at most this long


def public_packages() -> list[str]:
    """``hystkit`` and its public subpackages that declare ``__all__``, in name order."""
    import hystkit

    found = [info.name for info in pkgutil.walk_packages(hystkit.__path__, "hystkit.")
             if info.ispkg and not any(part.startswith("_") for part in info.name.split("."))
             and hasattr(importlib.import_module(info.name), "__all__")]
    return ["hystkit", *sorted(found)]


def kind(obj: object) -> str:
    """``class``, ``function`` (a cached or wrapped one too), ``module`` or ``data``."""
    if inspect.isclass(obj):
        return "class"
    if inspect.isfunction(inspect.unwrap(obj)):
        return "function"
    return "module" if inspect.ismodule(obj) else "data"


def exported(package: str) -> dict[str, object]:
    """The functions and classes in `package`'s ``__all__``, by exported name."""
    module = importlib.import_module(package)
    objects = {name: getattr(module, name) for name in module.__all__}
    return {name: obj for name, obj in objects.items() if kind(obj) in ("class", "function")}


def constants(package: str) -> dict[str, object]:
    """The other values in `package`'s ``__all__`` (no modules), by exported name."""
    module = importlib.import_module(package)
    objects = {name: getattr(module, name) for name in module.__all__}
    return {name: obj for name, obj in objects.items() if kind(obj) == "data"}


def homes(packages: list[str], exports: dict[str, dict[str, object]]) -> dict[int, str]:
    """For each exported object (by ``id``), the qualified name it is documented under."""
    found: dict[int, list[tuple[str, str]]] = {}
    for package in packages:
        for name, obj in exports[package].items():
            found.setdefault(id(obj), []).append((package, name))
    result = {}
    for key, places in found.items():
        package, name = places[0]
        obj_module = getattr(exports[package][name], "__module__", "") or ""
        inside = [(p, n) for p, n in places if obj_module == p or obj_module.startswith(p + ".")]
        package, name = max(inside, key=lambda place: len(place[0])) if inside else places[0]
        result[key] = f"{package}.{name}"
    return result


def _autosummary(names: list[str], toctree: bool) -> list[str]:
    lines = [".. autosummary::"]
    if toctree:
        lines.append("   :toctree: generated")
    lines += ["   :nosignatures:", ""]
    lines += [f"   {name}" for name in names]
    return [*lines, ""]


def package_page(package: str, objects: dict[str, object], home: dict[int, str]) -> str:
    """The reST of one package's page."""
    lines = [package, "=" * len(package), "", f".. automodule:: {package}", "",
             f".. currentmodule:: {package}", ""]
    own = {name: obj for name, obj in objects.items() if home[id(obj)] == f"{package}.{name}"}
    for title, wanted in (("Classes", "class"), ("Functions", "function")):
        names = sorted((n for n, o in own.items() if kind(o) == wanted), key=str.lower)
        if names:
            lines += [f".. rubric:: {title}", "", *_autosummary(names, toctree=True)]
    elsewhere = sorted((home[id(o)] for n, o in objects.items() if n not in own),
                       key=str.lower)
    if elsewhere:
        lines += [".. rubric:: Also exported here, documented with their own package", "",
                  ".. currentmodule:: None", "", *_autosummary(elsewhere, toctree=False),
                  f".. currentmodule:: {package}", ""]
    values = constants(package)
    if values:
        lines += [".. rubric:: Constants", ""]
        for name in sorted(values, key=str.lower):
            shown = repr(values[name])
            lines += [f".. autodata:: {name}"]
            if len(shown) > MAX_VALUE_CHARS or "\n" in shown:
                lines += ["   :no-value:"]
            lines += [""]
    return "\n".join(lines)


# Where each exported class and function is documented (``id`` -> qualified name): filled by
# `write_pages`, read by `resolve_by_object`.
DOCUMENTED_AS: dict[int, str] = {}


def write_pages(app: Sphinx, config: object = None) -> None:
    folder = Path(app.srcdir) / FOLDER
    folder.mkdir(parents=True, exist_ok=True)
    packages = public_packages()
    exports = {package: exported(package) for package in packages}
    home = homes(packages, exports)
    DOCUMENTED_AS.update(home)
    written = set()
    for package in packages:
        path = folder / f"{package}.rst"
        text = package_page(package, exports[package], home)
        if not path.exists() or path.read_text(encoding="utf-8") != text:
            path.write_text(text, encoding="utf-8")  # unchanged pages keep their time: no rebuild
        written.add(path)
    for stale in set(folder.glob("*.rst")) - written:  # a package that no longer exists
        stale.unlink()
    stubs = {folder / "generated" / f"{name}.rst" for name in home.values()}
    for stale in set(folder.glob("generated/*.rst")) - stubs:  # an object no longer exported
        stale.unlink()


def _import(name: str) -> tuple[bool, object, object]:
    """Whether `name` (dotted) exists, the object and its owner (a class for a member, else
    None). A dataclass field exists though the class has no attribute of that name."""
    parts = name.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj: object = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        owner = None
        for attribute in parts[cut:]:
            if not hasattr(obj, attribute):
                fields = getattr(obj, "__dataclass_fields__", {})
                last = attribute is parts[-1]
                return (last and inspect.isclass(obj) and attribute in fields), None, obj
            owner, obj = obj, getattr(obj, attribute)
        return True, obj, owner if inspect.isclass(owner) else None
    return False, None, None


def _candidates(node: nodes.Element) -> list[str]:
    """The full names a Python reference can mean: as the Python domain searches them (the
    documented module and class), then from where the docstring is defined (a private
    module's names), then, in an autosummary row, as a member of that row's object."""
    target = node["reftarget"].lstrip(".~")
    module, cls = node.get("py:module") or "", node.get("py:class") or ""
    names = [f"{module}.{cls}.{target}"] if module and cls else []
    owner = _import(f"{module}.{cls}")[1] if module and cls else None
    defined_in = getattr(owner, "__module__", "") or ""
    for scope in (module, _docstring_of(node), defined_in):
        parts = scope.split(".") if scope else []
        names += [".".join([*parts[:cut], target]) for cut in range(len(parts), 0, -1)]
    row = next((a for a in _ancestors(node) if isinstance(a, nodes.row)), None)
    if row is not None:
        listed = row[0].astext().split("(")[0].strip()
        names.append(f"{listed if not module else module + '.' + listed}.{target}")
    names.append(target)
    return [n for n in names if n.startswith("hystkit.")]


def _ancestors(node: nodes.Node) -> list[nodes.Node]:
    found = []
    while node.parent is not None:
        node = node.parent
        found.append(node)
    return found


def _docstring_of(node: nodes.Node) -> str:
    """``hystkit.io._raw_reader.RawReader`` for a node from autodoc's "docstring of ..."."""
    try:
        source = get_node_source(node)
    except ValueError:  # a node with no source
        return ""
    return source.rpartition("docstring of ")[2].strip() if "docstring of " in source else ""


def resolve_by_object(app: Sphinx, env: BuildEnvironment, node: nodes.Element,
                      contnode: nodes.Element) -> nodes.Element | None:
    """A Python reference the domain could not resolve: to the object's documented name when
    the object is documented under another one (``hystkit.Recording`` ->
    ``hystkit.io.Recording``, a method through its class); plain text when it exists but is
    not in the reference (a private module's helper, a submodule's function not in any
    ``__all__``); left to warn (a broken reference) when no such object exists."""
    if node.get("refdomain") != "py":
        return None
    domain = env.get_domain("py")
    for name in _candidates(node):
        found, obj, owner = _import(name)
        if not found:
            continue
        documented = DOCUMENTED_AS.get(id(obj))
        if documented is None and owner is not None and id(owner) in DOCUMENTED_AS:
            documented = f"{DOCUMENTED_AS[id(owner)]}.{name.rpartition('.')[2]}"
        if documented is not None:
            ref = domain.resolve_xref(env, node["refdoc"], app.builder, "obj", documented,
                                      node, contnode)
            if ref is not None:
                return ref
        return contnode
    return None


_sphinx_extract_summary = autosummary.extract_summary
# The docstrings' abbreviations a first sentence does not end at ("eq. 5.10", "sec. 5.3").
ABBREVIATIONS = ("eq.", "eqs.", "sec.", "fig.", "figs.", "ch.", "cf.", "vs.", "no.", "e.g.",
                 "i.e.", "et al.", "approx.")
_ABBREVIATION_END = re.compile(rf"(?<![A-Za-z])(?:{'|'.join(map(re.escape, ABBREVIATIONS))})$",
                               re.IGNORECASE)


def extract_summary(doc: list[str], settings: object) -> str:
    """Autosummary's one-line summary, not cut at an abbreviation nor inside inline markup.

    Sphinx 9's ``extract_summary`` means to extend the first sentence while cutting it breaks
    inline markup, but checks the whole paragraph instead of the cut, so a period inside a
    literal (``F_2 ... F_n``) leaves an open ````` and a docutils warning; and "eq. 5.10" ends
    its sentence at "eq.". Same rule, checked on the cut, with the docstrings' abbreviations."""
    summary = _sphinx_extract_summary(doc, settings)
    if _complete(summary, settings):
        return summary
    stanza = " ".join(line.strip() for line in
                      "\n".join(doc).strip().split("\n\n")[0].splitlines())
    sentences = autosummary.periods_re.split(stanza)
    for count in range(1, len(sentences)):
        cut = ". ".join(sentences[:count]).rstrip(".") + "."
        if len(cut) > len(summary) and _complete(cut, settings):
            return autosummary.literal_re.sub(".", cut)
    return autosummary.literal_re.sub(".", stanza)


def drop_type_docstrings(app: Sphinx, what: str, name: str, obj: object, options: object,
                         lines: list[str]) -> None:
    """A constant has no docstring of its own: autodoc then shows its type's (``tuple``'s
    "Built-in immutable sequence", a family class's whole Parameters section); say only
    what it is an instance of when that is one of hystkit's classes."""
    if what not in ("data", "attribute") or inspect.isclass(obj) or inspect.isroutine(obj):
        return
    own = type(obj).__doc__
    if isinstance(own, str) and "\n".join(lines).strip() == inspect.cleandoc(own).strip():
        kind_of = type(obj)
        lines[:] = ([f"A :class:`~{kind_of.__module__}.{kind_of.__qualname__}`.", ""]
                    if kind_of.__module__.startswith("hystkit.") else [])


def _complete(summary: str, settings: object) -> bool:
    """Whether `summary` ends a sentence: not at an abbreviation, no inline markup left open."""
    if _ABBREVIATION_END.search(summary):
        return False
    return not any(autosummary._parse_summary([summary], settings).findall(nodes.system_message))


# |x|, |.|, |w| in prose: absolute values and norms, which reST would read as substitutions
_BARS = re.compile(r"(?<![\\|])\|(?=\S)([^|`]*?\S)\|(?!\|)")
_LITERALS = re.compile(r"(``.*?``|`[^`]*`)")


def escape_bars(app: Sphinx, what: str, name: str, obj: object, options: object,
                lines: list[str]) -> None:
    """``|x|`` in a docstring's prose stays ``|x|`` (an absolute value, a norm), not a reST
    substitution reference that nothing defines; inline literals, roles, literal blocks and
    doctests are left as they are."""
    block_indent = None
    for i, line in enumerate(lines):
        indent = len(line) - len(line.lstrip())
        if block_indent is not None and (not line.strip() or indent > block_indent):
            continue  # inside a literal block
        block_indent = indent if line.rstrip().endswith("::") else None
        if "|" not in line or line.lstrip().startswith((">>>", "...", "| ")):
            continue
        parts = _LITERALS.split(line)
        lines[i] = "".join(part if k % 2 else _BARS.sub(r"\\|\1\\|", part)
                           for k, part in enumerate(parts))


def setup(app: Sphinx) -> dict[str, object]:
    app.connect("config-inited", write_pages)
    app.connect("missing-reference", resolve_by_object)
    app.connect("autodoc-process-docstring", escape_bars, priority=400)  # before numpydoc
    app.connect("autodoc-process-docstring", drop_type_docstrings, priority=400)
    autosummary.extract_summary = extract_summary
    return {"parallel_read_safe": True, "parallel_write_safe": True}
