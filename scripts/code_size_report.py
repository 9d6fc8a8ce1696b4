#!/usr/bin/env python3
"""Reports the classes and functions of C++ headers that exceed a size target.

Usage:
    scripts/code_size_report.py [--class-lines N] [--function-lines N] [--all] [--fail-over] PATH...

Each PATH is a file or a folder (searched for *.hpp, *.h, *.hh, *.hxx, *.cpp, *.cc, *.cxx).
Prints every class/struct/union over --class-lines lines (500 by default) and every function
over --function-lines lines (80 by default) as "file:line: kind name: N lines", then the largest
class and the largest function seen. Exits 0 (a report only) unless --fail-over is given, in
which case it exits 1 when anything is over a target. --all lists every class and function.

The heuristic (no parser, standard library only):
  1. Comments, string and character literals (raw strings included) and preprocessor lines are
     blanked out, keeping the line structure.
  2. Braces are matched. For each "{" the "head" is the text since the last ";", "{" or "}" at
     the same depth (an initializer's "{...}" inside a head, e.g. a constructor's member
     initializer "x_{...}" or a default argument "= {}", is kept in the head as "{}").
  3. Only braces opened at namespace or class scope are classified (everything inside a function,
     lambdas and control statements included, counts as part of that function):
       - "namespace ..." or 'extern "C"': a namespace;
       - "enum ...": neither;
       - a head whose last "class|struct|union Name" is followed by no "(": a class;
       - a brace opened inside parentheses: an initializer;
       - a head with "(" whose text after the last top-level ")" holds only qualifiers
         (const, noexcept, override, ->, a trailing return type, requires ...) or a
         constructor's ": member(...)" initializer list (the head ending in ")" or "}"): a
         function;
       - anything else (a member's "x{...}", "= {...}"): an initializer.
  4. A class or function spans from the first line of its head (access specifiers and the
     template<...> line included, comments not) to the line of its closing brace, inclusive.
It misreads macros that expand to braces and unusual declarations; it is meant for a size
report, not for a verdict on every file.
"""

from __future__ import annotations

import argparse
import os
import re
import sys

EXTS = (".hpp", ".h", ".hh", ".hxx", ".cpp", ".cc", ".cxx")


def blank(text: str) -> str:
    """Comments, literals and preprocessor lines replaced by spaces (newlines kept)."""
    out = []
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c == "#":
            # a preprocessor line, with its continuations
            while i < n and text[i] != "\n":
                if text[i] == "\\" and i + 1 < n and text[i + 1] == "\n":
                    out.append(" \n")
                    i += 2
                    continue
                out.append(" ")
                i += 1
            continue
        if c == "\n":
            out.append(c)
            line_start = True
            i += 1
            continue
        if c in " \t":
            out.append(c)
            i += 1
            continue
        line_start = False
        if text.startswith("//", i):
            while i < n and text[i] != "\n":
                out.append(" ")
                i += 1
            continue
        if text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("".join(ch if ch == "\n" else " " for ch in text[i:j]))
            i = j
            continue
        m = re.match(r'(?:u8|u|U|L)?R"([^()\\ ]{0,16})\(', text[i:i + 24])
        if m and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            end = text.find(")" + m.group(1) + '"', i + m.end())
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append('"' + "".join(ch if ch == "\n" else " " for ch in text[i + 1:j - 1]) + '"')
            i = j
            continue
        if c in "\"'":
            # a digit separator (1'000) is no character literal
            if c == "'" and i > 0 and text[i - 1].isalnum() and i + 1 < n and text[i + 1].isalnum():
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(c + " " * max(0, j - i - 2) + c)
            i = j
            continue
        out.append(c)
        i += 1
    return "".join(out)


QUALIFIER_TAIL = re.compile(r"^(?:\s|const\b|noexcept\b|override\b|final\b|mutable\b|volatile\b|&|&&|->[^=;]*|requires\b[^=;]*)*$")
CLASS_HEAD = re.compile(r"\b(class|struct|union)\s+(?:\[\[[^\]]*\]\]\s*)?(\w+)[^()]*$", re.S)
ACCESS = re.compile(r"^\s*(?:(?:public|private|protected)\s*:(?!:)\s*)+")


def classify(head: str) -> tuple[str, str]:
    """(kind, name) of a brace at namespace or class scope given its head."""
    h = ACCESS.sub("", head).strip()
    if re.match(r"^(?:inline\s+)?namespace\b", h) or re.match(r'^extern\s+"', h):
        return "namespace", ""
    if re.search(r"\benum\b", h) and "(" not in h:
        return "enum", ""
    m = CLASS_HEAD.search(h)
    if m and "(" not in h[m.start():]:
        return "class", m.group(2)
    if "(" not in h:
        return "other", ""
    # the text after the last top-level ")"
    depth, last_close, first_open, first_close = 0, -1, -1, -1
    for k, ch in enumerate(h):
        if ch == "(":
            if depth == 0 and first_open < 0:
                first_open = k
            depth += 1
        elif ch == ")":
            depth -= 1
            if depth == 0:
                last_close = k
                if first_close < 0:
                    first_close = k
    name_m = re.search(r"(operator\s*(?:\(\)|[^\s(]+)|[~\w:]+)\s*(?:<[^()]*>)?\s*$", h[:first_open])
    name = name_m.group(1) if name_m else "?"
    if name in ("if", "for", "while", "switch", "catch", "return", "sizeof", "decltype", "alignof"):
        return "other", ""
    tail = h[last_close + 1:] if last_close >= 0 else ""
    after_params = h[first_close + 1:]
    if QUALIFIER_TAIL.match(tail) or (re.match(r"^[\s\w]*:(?!:)", after_params) and re.search(r"[)}]\s*$", h)):
        return "function", name
    return "other", ""


def scan(path: str):
    """Yields (kind, name, first line, last line) of the classes and functions of one file."""
    with open(path, encoding="utf-8", errors="replace") as f:
        text = blank(f.read())
    stack = []  # (kind, name, first line, head, enclosing paren depth) per open brace
    head_start = 0  # offset where the current head begins
    paren = 0
    line = 1
    head_parts: list[str] = []
    i = 0
    n = len(text)

    def scope_kind():
        return stack[-1][0] if stack else "namespace"

    head_first = None  # the line of the head's first character
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
        elif not c.isspace() and head_first is None and c not in ";{}":
            head_first = line
        if c == "(":
            paren += 1
        elif c == ")":
            paren = max(0, paren - 1)
        elif c == ":" and paren == 0 and not head_parts and not text.startswith("::", i) \
                and re.fullmatch(r"\s*(?:public|private|protected)\s*", text[head_start:i]):
            # an access specifier is no part of the next member's head
            head_parts, head_start, head_first = [], i + 1, None
        elif c == ";" and paren == 0:
            head_parts, head_start, head_first = [], i + 1, None
        elif c == "{":
            head = "".join(head_parts) + text[head_start:i]
            first = head_first if head_first is not None else line
            if scope_kind() in ("namespace", "class"):
                if paren > 0:
                    kind, name = "init", ""
                else:
                    kind, name = classify(head)
                    if kind == "other":
                        kind = "init"
            else:
                kind, name = "inner", ""
            stack.append((kind, name, first, head, paren))
            head_parts, head_start, head_first = [], i + 1, None
            paren = 0
        elif c == "}":
            if stack:
                kind, name, first, head, outer_paren = stack.pop()
                if kind in ("class", "function"):
                    yield kind, name, first, line
                if kind == "init":
                    # the initializer stays part of the enclosing head
                    head_parts, head_start, head_first = [head, "{}"], i + 1, first
                    paren = outer_paren
                else:
                    head_parts, head_start, head_first = [], i + 1, None
                    paren = 0
            else:
                head_parts, head_start, head_first = [], i + 1, None
        i += 1


def files_of(paths):
    for p in paths:
        if os.path.isdir(p):
            for root, dirs, names in os.walk(p):
                dirs.sort()
                for name in sorted(names):
                    if name.endswith(EXTS):
                        yield os.path.join(root, name)
        else:
            yield p


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("paths", nargs="+", help="files or folders")
    ap.add_argument("--class-lines", type=int, default=500, help="class/struct target (lines, default 500)")
    ap.add_argument("--function-lines", type=int, default=80, help="function target (lines, default 80)")
    ap.add_argument("--all", action="store_true", help="list every class and function, not only those over")
    ap.add_argument("--fail-over", action="store_true", help="exit 1 if anything is over a target")
    args = ap.parse_args(argv)

    over = 0
    largest = {"class": (0, ""), "function": (0, "")}
    for path in files_of(args.paths):
        for kind, name, first, last in scan(path):
            lines = last - first + 1
            where = f"{path}:{first}"
            if lines > largest[kind][0]:
                largest[kind] = (lines, f"{where}: {name}")
            limit = args.class_lines if kind == "class" else args.function_lines
            if lines > limit:
                over += 1
                print(f"{where}: {kind} {name}: {lines} lines (over {limit})")
            elif args.all:
                print(f"{where}: {kind} {name}: {lines} lines")
    for kind in ("class", "function"):
        n, what = largest[kind]
        print(f"largest {kind}: " + (f"{n} lines, {what}" if n else "none"))
    print(f"over target: {over}")
    return 1 if args.fail_over and over else 0


if __name__ == "__main__":
    sys.exit(main())
