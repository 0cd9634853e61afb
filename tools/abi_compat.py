#!/usr/bin/env python3
"""Checks that a new mechanica.h keeps the C ABI of an old one.

Usage: python3 tools/abi_compat.py OLD_HEADER NEW_HEADER

Every declaration of the old header must be present, identically, in the new one:
  - each mech_* function prototype (return type, name, parameter types and names);
  - each MECH_* macro constant and its value;
  - each typedef (a scalar alias such as `typedef int32_t mech_frame_t;`, or an opaque
    handle `typedef struct mech_tree_t mech_tree_t;`);
  - each struct layout (field types and names, in order);
  - the MECH_FEATURE_* guard each of them is declared under.
Whitespace, declaration order and documentation comments may differ. New declarations are
allowed and listed. The exit status is 0 when the new header is compatible, 1 when it is not
and 2 for a usage error.
"""

import re
import sys

FEATURE_GUARD = re.compile(r"defined\((MECH_FEATURE_\w+)\)")


def strip_comments(text):
    """The header text with /* */ and // comments replaced by spaces (lines kept)."""
    text = re.sub(r"/\*.*?\*/", lambda m: re.sub(r"[^\n]", " ", m.group(0)), text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def normalize(code):
    """One canonical spelling of a C fragment: single spaces, none inside brackets or before
    punctuation, `T *x` for pointers."""
    code = re.sub(r"\s+", " ", code).strip()
    code = re.sub(r"\s*([(),;{}\[\]])\s*", r"\1", code)
    code = re.sub(r"\s*\*\s*", " *", code)
    return code


class Declarations:
    """The ABI-relevant declarations of one header, each with the feature guards around it."""

    def __init__(self):
        self.functions = {}
        self.constants = {}
        self.typedefs = {}
        self.structs = {}

    def kinds(self):
        return [
            ("function", self.functions),
            ("constant", self.constants),
            ("typedef", self.typedefs),
            ("struct", self.structs),
        ]


def statements(text):
    """Yields (guards, statement) for each preprocessor line and each C statement, where guards
    is the sorted tuple of MECH_FEATURE_* macros required by the enclosing #if blocks."""
    stack = []
    pending = []
    depth = 0
    for line in strip_comments(text).splitlines():
        stripped = line.strip()
        if stripped.startswith("#"):
            directive = stripped[1:].strip()
            if directive.startswith(("if", "ifdef", "ifndef")):
                stack.append(FEATURE_GUARD.findall(directive) if directive.startswith("if ") else [])
            elif directive.startswith("endif"):
                if stack:
                    stack.pop()
            elif directive.startswith("define"):
                yield current_guards(stack), stripped
            continue
        if not stripped or stripped == 'extern "C" {' or stripped == "}":
            continue  # blank lines and the C++ linkage block around the functions
        pending.append(stripped)
        depth += stripped.count("{") - stripped.count("}")
        if depth == 0 and stripped.endswith(";"):
            yield current_guards(stack), " ".join(pending)
            pending = []


def current_guards(stack):
    return tuple(sorted({g for frame in stack for g in frame}))


def parse(text):
    """The declarations of a header text."""
    found = Declarations()
    for guards, statement in statements(text):
        if statement.startswith("#"):
            m = re.match(r"#\s*define\s+(MECH_\w+)\s*(.*)$", statement)
            if m:
                found.constants[m.group(1)] = (guards, normalize(m.group(2)))
            continue
        m = re.match(r"typedef\s+struct\s+(\w+)\s*\{(.*)\}\s*(\w+)\s*;$", statement, flags=re.S)
        if m:
            found.structs[m.group(3)] = (guards, normalize(m.group(2)))
            continue
        m = re.match(r"typedef\s+(.*?)\s*(\w+)\s*;$", statement, flags=re.S)
        if m:
            found.typedefs[m.group(2)] = (guards, normalize(m.group(1)))
            continue
        m = re.search(r"\b(mech_\w+)\s*\(", statement)
        if m and statement.endswith(");"):
            found.functions[m.group(1)] = (guards, normalize(statement))
    return found


def describe(entry):
    guards, body = entry
    where = " && ".join(guards) if guards else "always"
    return f"[{where}] {body}"


def compare(old, new):
    """(problems, additions): what the new header broke, and what it added."""
    problems, additions = [], []
    for kind, old_items in old.kinds():
        new_items = dict(new.kinds())[kind]
        for name, entry in sorted(old_items.items()):
            if name not in new_items:
                problems.append(f"{kind} {name} is missing (was {describe(entry)})")
            elif new_items[name] != entry:
                problems.append(
                    f"{kind} {name} changed:\n    old {describe(entry)}\n    new {describe(new_items[name])}"
                )
        for name, entry in sorted(new_items.items()):
            if name not in old_items:
                additions.append(f"{kind} {name}: {describe(entry)}")
    return problems, additions


def main(argv):
    if len(argv) != 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    with open(argv[1], encoding="utf-8") as f:
        old = parse(f.read())
    with open(argv[2], encoding="utf-8") as f:
        new = parse(f.read())
    if not old.functions or not old.constants:
        print(f"{argv[1]}: found no functions or constants; is it mechanica.h?", file=sys.stderr)
        return 2
    problems, additions = compare(old, new)
    counts = ", ".join(f"{len(items)} {kind}s" for kind, items in old.kinds())
    print(f"old header: {counts}")
    for line in additions:
        print(f"added {line}")
    for line in problems:
        print(f"INCOMPATIBLE: {line}")
    if problems:
        print(f"{len(problems)} incompatible change(s)")
        return 1
    print(f"compatible: every old declaration is unchanged; {len(additions)} addition(s)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
