#!/usr/bin/env python3
"""Dependency graph of the modal crate's modules, and a check that it has no cycle.

Reads every `.rs` file under crates/mechanica-modal/src (or the directory given as the first
argument), drops comments, string literals and every item marked `#[cfg(test)]` (the unit tests
may use anything), and collects the paths that start with `crate::`, `super::` or `self::`, in
`use` declarations and inline. Each path is resolved to the file that defines the item,
following re-exports (`pub use` in a parent module or in lib.rs). That gives two graphs:

- concepts: the top-level modules (spectrum, certify, refine, dense, sparse, linalg, runtime,
  problem, error, ...), an edge when a file of one uses an item of another;
- files: an edge when one file uses an item defined in another.

Prints both graphs (each concept's dependencies, and a topological order) and every cycle
(strongly connected component of more than one node). Exits with status 1 when there is a
cycle, 0 otherwise.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_SOURCE = ROOT / "crates" / "mechanica-modal" / "src"

ITEM_KEYWORDS = ("fn", "struct", "enum", "trait", "type", "const", "static", "mod", "union", "macro_rules!")


def strip_comments_and_strings(text: str) -> str:
    """The source with comments removed and string literals emptied (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            end = text.find("\n", i)
            i = n if end < 0 else end
        elif text.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    if text[i] == "\n":
                        out.append("\n")
                    i += 1
        elif c == "r" and re.match(r'r#*"', text[i:]) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            hashes = re.match(r'r(#*)"', text[i:]).group(1)
            end = text.find('"' + hashes, i + 2 + len(hashes))
            end = n if end < 0 else end + 1 + len(hashes)
            out.append('""' + "\n" * text.count("\n", i, end))
            i = end
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j + 1
        elif c == "'" and re.match(r"'(\\.|[^\\'])'", text[i:]):
            # A character literal (a lifetime has no closing quote).
            m = re.match(r"'(\\.|[^\\'])'", text[i:])
            out.append("' '")
            i += m.end()
        else:
            out.append(c)
            i += 1
    return "".join(out)


def item_end(text: str, start: int) -> int:
    """The end of the item beginning at `start`: its closing brace, or its `;`."""
    i, depth = start, 0
    while i < len(text):
        c = text[i]
        if c == "{":
            depth += 1
        elif c == "}":
            depth -= 1
            if depth == 0:
                return i + 1
        elif c == ";" and depth == 0:
            return i + 1
        i += 1
    return len(text)


TEST_ATTRIBUTE = re.compile(r"#\[cfg\(\s*(all\(\s*)?test\b")


def drop_test_items(text: str) -> tuple[str, list[str]]:
    """The text without `#[cfg(test)]` items, and the names of test-only file modules."""
    skipped_modules = []
    while True:
        m = TEST_ATTRIBUTE.search(text)
        if not m:
            return text, skipped_modules
        attribute_end = text.find("]", m.end()) + 1
        end = item_end(text, attribute_end)
        declared = re.match(r"\s*(pub(\([^)]*\))?\s+)?mod\s+(\w+)\s*;", text[attribute_end:end])
        if declared:
            skipped_modules.append(declared.group(3))
        text = text[: m.start()] + "\n" * text.count("\n", m.start(), end) + text[end:]


def expand_use_tree(tree: str) -> list[tuple[list[str], str]]:
    """`a::{b, c::{d as e}}` → [(['a','b'], 'b'), (['a','c','d'], 'e')]."""
    # Spaces matter only around `as`: mark it, then drop the rest.
    tree = re.sub(r"\s+as\s+", "@", tree.strip())
    tree = re.sub(r"\s+", "", tree)

    def split_top(s: str) -> list[str]:
        parts, depth, current = [], 0, ""
        for ch in s:
            if ch == "," and depth == 0:
                parts.append(current)
                current = ""
                continue
            depth += ch == "{"
            depth -= ch == "}"
            current += ch
        if current:
            parts.append(current)
        return parts

    def walk(prefix: list[str], s: str) -> list[tuple[list[str], str]]:
        brace = s.find("{")
        if brace >= 0 and s.endswith("}"):
            head = [p for p in s[:brace].split("::") if p]
            out = []
            for part in split_top(s[brace + 1 : -1]):
                out.extend(walk(prefix + head, part))
            return out
        alias = None
        if "@" in s:
            s, alias = s.split("@", 1)
        segments = [p for p in s.split("::") if p]
        if segments and segments[-1] == "self":
            segments = segments[:-1]
        if not segments:
            return []
        return [(prefix + segments, alias or segments[-1])]

    return walk([], tree)


class Module:
    def __init__(self, path: list[str], file: Path, text: str):
        self.path = path
        self.file = file
        self.text = text
        self.children: dict[str, Module] = {}
        self.imports: dict[str, list[str]] = {}  # name in scope → absolute path
        self.defined: set[str] = set()
        self.references: list[list[str]] = []  # absolute paths used


def load(source: Path) -> dict[tuple[str, ...], Module]:
    modules: dict[tuple[str, ...], Module] = {}
    for file in sorted(source.rglob("*.rs")):
        relative = file.relative_to(source).with_suffix("")
        parts = list(relative.parts)
        if parts == ["lib"]:
            path = ["crate"]
        elif parts[-1] == "mod":
            path = ["crate"] + parts[:-1]
        else:
            path = ["crate"] + parts
        raw = strip_comments_and_strings(file.read_text(encoding="utf-8"))
        text, test_modules = drop_test_items(raw)
        modules[tuple(path)] = Module(path, file, text)
        modules[tuple(path)].test_modules = test_modules
    # Test-only file modules (`#[cfg(test)] mod tests;`) and their descendants are dropped.
    for module in list(modules.values()):
        for name in getattr(module, "test_modules", []):
            prefix = tuple(module.path + [name])
            for key in [k for k in modules if k[: len(prefix)] == prefix]:
                del modules[key]
    for key, module in modules.items():
        if len(key) > 1 and key[:-1] in modules:
            modules[key[:-1]].children[key[-1]] = module
    return modules


def absolute(module: Module, segments: list[str]) -> list[str] | None:
    """The absolute path of `segments` as written in `module`; None for external crates."""
    if not segments:
        return None
    head = segments[0]
    if head == "crate":
        return segments
    if head in ("self", "super"):
        base = list(module.path)
        rest = list(segments)
        while rest and rest[0] in ("self", "super"):
            if rest.pop(0) == "super":
                base = base[:-1]
        return base + rest
    if head in module.children:
        return module.path + segments
    return None


USE = re.compile(r"\b(?:pub(?:\([^)]*\))?\s+)?use\s+([^;]+);")
INLINE = re.compile(r"(?<![\w:])((?:crate|super|self)(?:::\w+)+)")
DEFINITION = re.compile(r"\b(?:fn|struct|enum|trait|type|const|static|mod|union)\s+(\w+)")


INLINE_MODULE = re.compile(r"\bmod\s+(\w+)\s*\{")


def inline_modules(text: str) -> list[tuple[int, int, str]]:
    """(start, end, name) of every inline `mod name { ... }` block."""
    spans = []
    for m in INLINE_MODULE.finditer(text):
        spans.append((m.start(), item_end(text, m.start()), m.group(1)))
    return spans


def scope_at(module: Module, spans: list[tuple[int, int, str]], position: int) -> Module:
    """`module`, or the inline module (as a child scope) that encloses `position`."""
    path = list(module.path)
    for start, end, name in spans:
        if start <= position < end:
            path.append(name)
    if path == module.path:
        return module
    scope = Module(path, module.file, "")
    scope.children = module.children
    return scope


def collect(modules: dict[tuple[str, ...], Module]) -> None:
    for module in modules.values():
        module.defined = set(DEFINITION.findall(module.text))
        spans = inline_modules(module.text)
        without_uses = list(module.text)
        for m in USE.finditer(module.text):
            scope = scope_at(module, spans, m.start())
            for segments, name in expand_use_tree(m.group(1)):
                target = absolute(scope, segments)
                if target is None:
                    continue
                if scope is module:
                    module.imports[name] = target
                module.references.append(target)
            without_uses[m.start() : m.end()] = " " * (m.end() - m.start())
        text = "".join(without_uses)
        for m in INLINE.finditer(text):
            target = absolute(scope_at(module, spans, m.start()), m.group(1).split("::"))
            if target is not None:
                module.references.append(target)


def resolve(modules: dict[tuple[str, ...], Module], path: list[str], depth: int = 0) -> Module | None:
    """The module (file) that defines the item at `path`, following re-exports."""
    if depth > 20 or not path or path[0] != "crate":
        return None
    current = modules.get(("crate",))
    for i, segment in enumerate(path[1:], start=1):
        if current is None:
            return None
        if segment in current.children:
            current = current.children[segment]
            continue
        if segment in current.imports and segment not in current.defined:
            return resolve(modules, current.imports[segment] + path[i + 1 :], depth + 1)
        return current
    return current


def concept(module: Module) -> str:
    return module.path[1] if len(module.path) > 1 else "lib"


def file_name(module: Module, source: Path) -> str:
    return str(module.file.relative_to(source))


def strongly_connected(graph: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's strongly connected components with more than one node."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                components.append(sorted(component))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return components


def topological_layers(graph: dict[str, set[str]]) -> list[list[str]]:
    """Nodes by layer: each depends only on nodes of earlier layers (acyclic graphs only)."""
    remaining = {v: set(ws) - {v} for v, ws in graph.items()}
    layers = []
    while remaining:
        ready = sorted(v for v, ws in remaining.items() if not ws & remaining.keys())
        if not ready:
            break
        layers.append(ready)
        for v in ready:
            del remaining[v]
    return layers


def main() -> int:
    source = Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_SOURCE
    modules = load(source)
    collect(modules)
    concepts: dict[str, set[str]] = {}
    files: dict[str, set[str]] = {}
    for module in modules.values():
        own_concept, own_file = concept(module), file_name(module, source)
        concepts.setdefault(own_concept, set())
        files.setdefault(own_file, set())
        for reference in module.references:
            target = resolve(modules, reference)
            if target is None or target is module:
                continue
            # lib.rs only declares modules and re-exports them: its edges are not dependencies.
            if concept(module) == "lib":
                continue
            target_concept, target_file = concept(target), file_name(target, source)
            if target_concept != own_concept and target_concept != "lib":
                concepts[own_concept].add(target_concept)
            if target_file != "lib.rs":
                files[own_file].add(target_file)
    concepts.pop("lib", None)
    files.pop("lib.rs", None)

    print("Concept dependencies (module: the modules it uses)")
    for name in sorted(concepts):
        print(f"  {name:10} -> {', '.join(sorted(concepts[name])) or '(none)'}")
    concept_cycles = strongly_connected(concepts)
    file_cycles = strongly_connected(files)
    if not concept_cycles:
        print("Concept layers, bottom first (each uses only earlier layers):")
        for i, layer in enumerate(topological_layers(concepts)):
            print(f"  {i}: {', '.join(layer)}")
    print(f"File dependencies: {len(files)} files, {sum(len(v) for v in files.values())} edges")
    for name in sorted(files):
        if files[name]:
            print(f"  {name} -> {', '.join(sorted(files[name]))}")
    status = 0
    for kind, cycles in (("concept", concept_cycles), ("file", file_cycles)):
        for cycle in cycles:
            print(f"CYCLE between {kind}s: {' <-> '.join(cycle)}")
            status = 1
    print("No cycle." if status == 0 else "Cycles found.")
    return status


if __name__ == "__main__":
    sys.exit(main())
