#!/usr/bin/env python3
"""The plain checks of the code's shape: no source file over MAX_FILE lines, no function over
MAX_FUNCTION lines (from its opening brace to its closing one), and the library's module order: a
module of vdbhair/ includes only itself, the core headers (vdbhair/*.h) and modules below it.

  scripts/code_shape.py [--max-file N] [--max-function N] [--list K] [ROOT]

Reads every .h, .cc and .cpp under ROOT's vdbhair/, apps/, python/ and tests/. A function is a
brace block opened after a parameter list (`) {`, `) const {`, `) noexcept {`, `-> T {`, or a
constructor's initializer list) that is not inside another function; lambdas count with the
function that holds them. Comments, strings and character literals are skipped. Exit 1 and one line
per offence when a limit is broken; --list K prints the K longest functions either way.
"""
import argparse
import os
import re
import sys

DIRS = ("vdbhair", "apps", "python", "tests")

# The library's modules, lowest first. A module may include a module of a lower rank, never one of
# its own rank (siblings) or above; the core headers (vdbhair/*.h) are below them all.
LAYERS = (("strands",), ("io",), ("field",), ("scalp",), ("helicoid",), ("compare",), ("synth",), ("render", "dataset"))
RANK = {m: r for r, group in enumerate(LAYERS) for m in group}
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]vdbhair/(\w+)/', re.M)
EXTS = (".h", ".cc", ".cpp")


def strip(text):
    """The text with comments, string and character literals blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = ")" + m.group(1) + '"'
            j = text.find(end, i + m.end())
            j = n if j < 0 else j + len(end)
            out.append('""' + re.sub(r"[^\n]", " ", text[i + 2:j]))
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # digit separator 1'000
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(c + " " * (j - i - 2) + c if j - i >= 2 else c)
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


HEAD_FUNC = re.compile(
    r"(\)\s*(const|noexcept|override|final|mutable|\s)*(->\s*[\w:<>,\s\*&]+)?"
    r"|\)\s*:\s*[\w:]+[\s\S]*\)|\bmain\s*\(.*\))\s*$")


def functions(src):
    """(name, first line, line count) of each outermost function body in stripped source."""
    found = []
    stack = []  # per open brace: True when it opened a function body not inside another
    in_function = 0
    line = 1
    last = 0  # offset after the previous ';', '{' or '}'
    for i, c in enumerate(src):
        if c == "\n":
            line += 1
        elif c == "{":
            head = src[last:i]
            is_func = False
            if in_function == 0:
                h = head.strip()
                if not re.match(r"^(namespace|extern|struct|class|union|enum)\b", h.split("\n")[-1].strip()) \
                        and not re.search(r"\b(namespace|struct|class|union|enum)\b[^()]*$", h) \
                        and not h.endswith("=") and re.search(r"\)\s*[\w\s:<>,\*&\-\(\)\{\}\.]*$", h) \
                        and not re.search(r"^\s*(if|for|while|switch)\b", h):
                    is_func = True
            if is_func:
                name = re.search(r"([~\w:]+(?:operator\S*)?)\s*\((?:[^()]|\([^()]*\))*\)[^()]*$", head)
                stack.append(("f", line, name.group(1) if name else "?"))
                in_function += 1
            else:
                stack.append(("b", line, ""))
            last = i + 1
        elif c == "}":
            if stack:
                kind, start, name = stack.pop()
                if kind == "f":
                    in_function -= 1
                    found.append((name, start, line - start + 1))
            last = i + 1
        elif c == ";":
            last = i + 1
    return found


def layer_offences(rel, text):
    """One line per include of @a text (the file @a rel) that breaks the module order."""
    parts = rel.split(os.sep)
    if len(parts) < 3 or parts[0] != "vdbhair":
        return []
    own = parts[1]
    if own not in RANK:
        return [f"{rel}: module '{own}' has no place in code_shape.py's LAYERS"]
    out = []
    for m in INCLUDE.finditer(text):
        dep = m.group(1)
        if dep == own:
            continue
        if dep not in RANK:
            out.append(f"{rel}: includes module '{dep}', which has no place in LAYERS")
        elif RANK[dep] >= RANK[own]:
            line = text.count("\n", 0, m.start()) + 1
            out.append(f"{rel}:{line}: {own}/ includes {dep}/ (the order, lowest first: "
                       f"{' < '.join('/'.join(g) for g in LAYERS)})")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("root", nargs="?", default=os.path.join(os.path.dirname(__file__), ".."))
    ap.add_argument("--max-file", type=int, default=800)
    ap.add_argument("--max-function", type=int, default=120)
    ap.add_argument("--list", type=int, default=0, metavar="K")
    args = ap.parse_args()
    root = os.path.abspath(args.root)
    offences, all_funcs, nfiles = [], [], 0
    for d in DIRS:
        for dirpath, _, files in os.walk(os.path.join(root, d)):
            for f in sorted(files):
                if not f.endswith(EXTS):
                    continue
                path = os.path.join(dirpath, f)
                rel = os.path.relpath(path, root)
                with open(path, encoding="utf-8", errors="replace") as fh:
                    text = fh.read()
                nfiles += 1
                offences += layer_offences(rel, text)
                lines = text.count("\n")
                if lines > args.max_file:
                    offences.append(f"{rel}: {lines} lines (the rule: at most {args.max_file})")
                for name, start, length in functions(strip(text)):
                    all_funcs.append((length, rel, start, name))
                    if length > args.max_function:
                        offences.append(f"{rel}:{start}: {name} is {length} lines "
                                        f"(the rule: at most {args.max_function})")
    if nfiles == 0:
        print(f"code_shape: no source files under {root}", file=sys.stderr)
        return 2
    for length, rel, start, name in sorted(all_funcs, reverse=True)[:args.list]:
        print(f"{length:5d} {rel}:{start} {name}")
    for o in offences:
        print(o, file=sys.stderr)
    print(f"code_shape: {nfiles} files, {len(all_funcs)} functions, {len(offences)} over the limits",
          file=sys.stderr)
    return 1 if offences else 0


if __name__ == "__main__":
    sys.exit(main())
