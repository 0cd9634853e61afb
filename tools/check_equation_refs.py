#!/usr/bin/env python3
"""Checks that every equation label cited in the code and docs is defined in docs/theory.md.

Usage: python3 tools/check_equation_refs.py [--verbose] [--root DIR]

Scanned: the comments and string literals of crates/**/*.rs, benches/**/*.rs and
ffi-tests/**/*.rs, the comments of include/*.h, and docs/*.md and README.md (all but
docs/theory.md itself and docs/benchmarks.md, whose tables hold ratios such as "(1.10)"; prose and the comments of fenced code, not `inline code`). Code outside
comments and strings is never read, so a literal such as `Some(1.5)` is not taken for
equation (1.5).

What counts as a citation:
- syllabus labels N.M (chapter 1-9, number 1-999, optional '*'): a list of labels or ranges
  "N.M–N.M" that starts a parenthesised group or a part of one ("(8.89)", "(7.61–7.71,
  7.87*–7.91*, 7.107)", "(normalised here; 3.22–3.23, 3.30)", "(5.16–5.23 on the normal
  components)"), or that follows the word "syllabus" or the words "remark after". A range
  counts as its two endpoints. A range whose endpoints lie in different chapters, or a number
  followed by a unit or a factor ("2.7–3.4× faster", "0.21–0.24 s"), is not a citation;
- syllabus sections "§8e", "§8f–g", "syllabus 5c–d and 7h–k" (both ends of a range of
  letters);
- "EB1911 (13)" and "EB1911 §22 (15)", with ranges "EB1911 (15)–(16)";
- "FM 4.61" and "FM 4.83–4.86";
- "(M.3)" and "(M.4)–(M.7)", the project's own equations of "Integration in time".

A label is defined when docs/theory.md states it: in bold where its equation is given,
"**(8.89)**" ("**`(7.87*)`**" for a starred label), "**EB1911 (13)**", "**EB1911 §22 (15)**",
"**FM 4.61**", or, for a section, as the start of a heading "### §8e ..." (a range of letters
"### §8b–d" defines each end). A range "**(8.84)**–**(8.92)**" defines its two ends only. The script prints every label that is cited but not defined, with the places that
cite it, and exits with status 1 if there is any.
"""

import argparse
import pathlib
import re
import sys

NUMBER = r"[1-9]\.[1-9][0-9]{0,2}\*?"
RANGE = rf"(?P<first>{NUMBER})(?:\s*[–-]\s*(?P<last>{NUMBER}))?"
RANGE_RE = re.compile(RANGE)
PLAIN_RANGE = rf"{NUMBER}(?:\s*[–-]\s*{NUMBER})?"
# What may not follow a label inside a group: a unit, a factor, an operator or a digit.
UNIT_AFTER = re.compile(r"\s*(?:[×x%+*/=<>≈±]|s\b|ms\b|µs\b|us\b|ns\b|Hz\b|GB\b|MB\b|kB\b|[0-9])")
PREFIX = re.compile(r"\s*(?:syllabus|see|cf\.|remark after)\s+", re.IGNORECASE)
LIST = rf"(?<![0-9.]){PLAIN_RANGE}(?:(?:\s*[,;]\s*|\s+and\s+){PLAIN_RANGE})*"
# Words after which a list of labels is a citation even outside parentheses; after the weak
# ones the list must end at punctuation ("S_n in 7.96)" but not "in 2.1 M triangles").
STRONG_KEYWORD_LIST = re.compile(rf"(?:syllabus|remark after|those of|form of)\s+({LIST})")
WEAK_KEYWORD_LIST = re.compile(rf"\b(?:in|from|of)\s+({LIST})(?=\s*(?:[).;:]|,\s|$))", re.M)
SECTION = r"[1-9][a-k](?:\s*[–-]\s*[a-k])?(?![0-9a-z.])"
SECTION_LIST_RE = re.compile(rf"(?:§\s*|syllabus\s+)({SECTION}(?:(?:\s*,\s*§?|\s+and\s+§?){SECTION})*)")
SECTION_RE = re.compile(r"(?P<chapter>[1-9])(?P<first>[a-k])(?:\s*[–-]\s*(?P<last>[a-k]))?")
EB_RE = re.compile(r"EB1911\s*(?P<section>§\s*2[12]\s*)?\((?P<first>[0-9]{1,2})\)(?:\s*[–-]\s*\((?P<last>[0-9]{1,2})\))?")
FM_RE = re.compile(r"\bFM\s+(?P<first>4\.[0-9]{1,3})(?:\s*[–-]\s*(?P<last>4\.[0-9]{1,3}))?")
MOTION_RE = re.compile(r"\(M\.(?P<first>[0-9]{1,2})\)(?:\s*[–-]\s*\(M\.(?P<last>[0-9]{1,2})\))?")
THEORY_LABEL_RE = re.compile(rf"\(({NUMBER})\)")
# The last equation of each syllabus chapter: a number beyond it is not a syllabus label.
LAST_EQUATION = {1: 43, 2: 37, 3: 41, 4: 53, 5: 61, 6: 33, 7: 117, 8: 93, 9: 39}


def in_syllabus(label):
    chapter, number = label.strip("()*").split(".")
    return int(number) <= LAST_EQUATION[int(chapter)]


def rust_text(source):
    """The comments and string literals of Rust source, other characters blanked (newlines kept)."""
    out = []
    i, n = 0, len(source)
    keep = lambda s: out.append(s)
    blank = lambda s: out.append("".join(c if c == "\n" else " " for c in s))
    while i < n:
        c = source[i]
        if source.startswith("//", i):
            j = source.find("\n", i)
            j = n if j < 0 else j
            keep(source[i:j])
            i = j
        elif source.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if source.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif source.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            keep(source[i:j])
            i = j
        elif re.match(r'r#*"', source[i:i + 8]) and (i == 0 or not (source[i - 1].isalnum() or source[i - 1] == "_")):
            hashes = re.match(r'r(#*)"', source[i:]).group(1)
            end = source.find('"' + hashes, i + 2 + len(hashes))
            end = n if end < 0 else end + 1 + len(hashes)
            keep(source[i:end])
            i = end
        elif c == '"':
            j = i + 1
            while j < n and source[j] != '"':
                j += 2 if source[j] == "\\" else 1
            keep(source[i:j + 1])
            i = j + 1
        elif c == "'":
            literal = re.match(r"'(?:\\.|\\u\{[0-9a-fA-F]+\}|[^\\'])'", source[i:])
            j = i + (len(literal.group(0)) if literal else 1)
            blank(source[i:j])
            i = j
        else:
            blank(c)
            i += 1
    return "".join(out)


def c_comment_text(source):
    """The comments of a C header, other characters blanked (newlines kept)."""
    out = []
    for match in re.finditer(r"/\*.*?\*/|//[^\n]*|\n|[^/\n]+|/", source, re.S):
        token = match.group(0)
        if token.startswith("/*") or token.startswith("//"):
            out.append(token)
        else:
            out.append("".join(c if c == "\n" else " " for c in token))
    return "".join(out)


def markdown_text(source):
    """Markdown prose without inline code spans, plus the comments and strings of fenced code
    blocks."""
    parts = re.split(r"(^```[^\n]*\n.*?^```[ \t]*$)", source, flags=re.S | re.M)
    blank_code = lambda m: " " * len(m.group(0))
    return "".join(rust_text(p) if p.startswith("```") else re.sub(r"`[^`\n]*`", blank_code, p) for p in parts)


def endpoints(match):
    first, last = match.group("first"), match.group("last")
    return [first] if last is None else [first, last]


def same_chapter(labels):
    return len({label.split(".")[0] for label in labels}) == 1


def group_contents(text):
    """Each parenthesised group's own text, up to its ')', the first nested '(' or 300
    characters; a group continues over line breaks, without the next line's comment marker."""
    for match in re.finditer(r"\(", text):
        start = match.end()
        window = re.sub(r"\n\s*(?://[/!]?|\*(?!/))?", " ", text[start:start + 300])
        stop = re.search(r"[()]", window)
        yield start, window[:stop.start()] if stop else window


def label_part(part):
    """The labels of one part of a group when it starts with a label or a range, else None."""
    prefix = PREFIX.match(part)
    rest = part[prefix.end():] if prefix else part.lstrip()
    match = RANGE_RE.match(rest)
    if not match:
        return None
    after = rest[match.end():]
    if after and not after[0].isspace() and after[0] not in ".):":
        return None
    if UNIT_AFTER.match(after) or re.search(r"[0-9]\.[0-9]", after):
        return None
    labels = endpoints(match)
    return (match.group(0), labels) if same_chapter(labels) else None


def labels_in_group(group):
    """Syllabus labels of a parenthesised group. A part counts when it starts with a label or a
    range and is the group's first part, follows a ';', follows a part that counted, or
    follows a ',' with only label parts after it ("(König, 3.37, 3.41)")."""
    pieces = re.split(r"(;|,|\s+and\s+|\s+with\s+)", group)
    parts = [label_part(pieces[i]) for i in range(0, len(pieces), 2)]
    separators = [""] + [pieces[i].strip() for i in range(1, len(pieces), 2)]
    found, previous_counted = [], True
    for index, part in enumerate(parts):
        trailing = separators[index] == "," and all(p is not None for p in parts[index:])
        counted = part is not None and (index == 0 or separators[index] == ";" or previous_counted or trailing)
        if counted:
            found.append(part)
        previous_counted = counted
    return found


def citations(text):
    """(kind, label, matched text, offset) for every citation in `text`."""
    found = []
    for start, group in group_contents(text):
        for matched, labels in labels_in_group(group):
            found += [("syllabus", f"({label})", matched, start) for label in labels]
    for keyword_list in (STRONG_KEYWORD_LIST, WEAK_KEYWORD_LIST):
        for match in keyword_list.finditer(text):
            for item in RANGE_RE.finditer(match.group(1)):
                labels = endpoints(item)
                if same_chapter(labels):
                    found += [("syllabus", f"({label})", item.group(0), match.start()) for label in labels]
    for listed in SECTION_LIST_RE.finditer(text):
        for match in SECTION_RE.finditer(listed.group(1)):
            letters = [match.group("first")] + ([match.group("last")] if match.group("last") else [])
            found += [("section", f"§{match.group('chapter')}{letter}", match.group(0), listed.start()) for letter in letters]
    for match in EB_RE.finditer(text):
        section = "§22 " if match.group("section") and "22" in match.group("section") else ""
        found += [("EB1911", f"EB1911 {section}({number})", match.group(0), match.start()) for number in endpoints(match)]
    for match in FM_RE.finditer(text):
        found += [("FM", f"FM {number}", match.group(0), match.start()) for number in endpoints(match)]
    for match in MOTION_RE.finditer(text):
        found += [("motion", f"(M.{number})", match.group(0), match.start()) for number in endpoints(match)]
    return found


def scanned_files(root):
    files = []
    for pattern in ("crates/**/*.rs", "benches/**/*.rs", "ffi-tests/**/*.rs"):
        files += [(p, rust_text) for p in sorted(root.glob(pattern)) if "target" not in p.parts]
    files += [(p, c_comment_text) for p in sorted(root.glob("include/*.h"))]
    files += [(p, markdown_text) for p in sorted(root.glob("docs/*.md")) if p.name not in ("theory.md", "benchmarks.md")]
    files += [(p, markdown_text) for p in [root / "README.md"] if p.exists()]
    return files


def defined_labels(theory):
    """The labels that docs/theory.md states: a bold label "**(8.89)**" (or "**`(7.87*)`**" for a
    starred one), "**EB1911 (13)**", "**EB1911 §22 (15)**", "**FM 4.61**", and a section heading
    "### §8e ..." for a section. A label that is only mentioned in passing does not count."""
    labels = {f"({label})" for label in re.findall(rf"\*\*`?\(({NUMBER})\)`?\*\*", theory)}
    labels |= {f"§{c}{l}" for c, l in re.findall(r"^#+ §([1-9])([a-k])(?![0-9a-z.])", theory, re.M)}
    labels |= {f"§{c}{l}" for c, first, last in re.findall(r"^#+ §([1-9])([a-k])–([a-k])", theory, re.M)
               for l in (first, last)}
    labels |= {f"EB1911 ({n})" for n in re.findall(r"\*\*EB1911 \(([0-9]{1,2})\)\*\*", theory)}
    labels |= {f"EB1911 §22 ({n})" for n in re.findall(r"\*\*EB1911 §22 \(([0-9]{1,2})\)\*\*", theory)}
    labels |= {f"FM {n}" for n in re.findall(r"\*\*FM (4\.[0-9]{1,3})\*\*", theory)}
    labels |= {f"(M.{n})" for n in re.findall(r"\*\*\(M\.([0-9]{1,2})\)\*\*", theory)}
    return labels


def sort_key(label):
    numbers = [int(x) for x in re.findall(r"[0-9]+", label)]
    return (label.split(" ")[0].strip("(§"), numbers, label)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--root", default=pathlib.Path(__file__).resolve().parent.parent, type=pathlib.Path)
    parser.add_argument("--verbose", action="store_true", help="list every matched citation")
    args = parser.parse_args()
    theory_path = args.root / "docs" / "theory.md"
    if not theory_path.exists():
        print(f"missing {theory_path}")
        return 1
    defined = defined_labels(theory_path.read_text(encoding="utf-8"))

    cited, outside = {}, {}
    for path, extract in scanned_files(args.root):
        text = extract(path.read_text(encoding="utf-8"))
        for kind, label, matched, offset in citations(text):
            line = text.count("\n", 0, offset) + 1
            place = f"{path.relative_to(args.root)}:{line}"
            target = cited if kind != "syllabus" or in_syllabus(label) else outside
            target.setdefault(label, []).append((place, matched, kind))

    if args.verbose:
        for label in sorted(cited, key=sort_key):
            places = sorted({f"{place} [{matched.strip()}]" for place, matched, _ in cited[label]})
            print(f"{label}: {len(places)} citation(s)")
            for place in places:
                print(f"    {place}")
    for label in sorted(outside, key=sort_key):
        places = sorted({place for place, _, _ in outside[label]})
        print(f"note: {label} at {', '.join(places)} is beyond the syllabus numbering; not treated as a citation")
    missing = sorted((label for label in cited if label not in defined), key=sort_key)
    print(f"{len(cited)} distinct labels cited; {len(defined)} defined in docs/theory.md; {len(missing)} missing")
    for label in missing:
        places = sorted({place for place, _, _ in cited[label]})
        print(f"missing {label}: cited at {', '.join(places[:5])}{' ...' if len(places) > 5 else ''}")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
