#!/usr/bin/env python3
"""Runs one group of command-line test cases: one CTest per group, one process per command.

    cli_suite.py CASES_FILE

CASES_FILE is written by tests/apps/CMakeLists.txt (vdbhair_cli_test): for each case a line
"case<TAB>NAME", one line "arg<TAB>VALUE" per argument, and a line "end". A case's arguments are

    [--exit N|nonzero] [--stdout RE]... [--no-stdout RE]... [--stderr RE]... [--stderr-lines N]
    [--absent PATH]... [--exists PATH]... [--keep PATH]... -- COMMAND [ARGS...]

  --exit N        the exit status the command must have (default 0; "nonzero": any but 0)
  --stdout RE     some line of stdout matches the extended regular expression RE (as `grep -E`)
  --no-stdout RE  no line of stdout matches RE
  --stderr RE     some line of stderr matches RE
  --stderr-lines N  stderr has exactly N lines
  --absent PATH   removed before the run, must not exist after it
  --exists PATH   must exist after the run
  --keep PATH     must exist before the run and be byte-identical after it

and no temporary output (".STEM.vdbhair-tmp-*") may be left next to any PATH named above.

Every case runs, in the order of the file, whatever the others do; the group fails if one does,
and the report names each failed case with its command, stdout and stderr. The environment variable
VDBHAIR_CLI_CASES=RE runs only the cases whose name matches RE (e.g. to rerun one failure).
"""
import hashlib
import os
import re
import subprocess
import sys
import time


OPTIONS_WITH_VALUE = {"--exit", "--stdout", "--no-stdout", "--stderr", "--stderr-lines", "--absent", "--exists", "--keep"}


def read_cases(path):
    cases, name, args = [], None, None
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            line = line.rstrip("\n")
            kind, _, value = line.partition("\t")
            if kind == "case" and name is None:
                name, args = value, []
            elif kind == "arg" and name is not None:
                args.append(value)
            elif kind == "end" and name is not None:
                cases.append((name, args))
                name = None
            else:
                raise SystemExit(f"cli_suite.py: {path}: line {number}: unexpected '{line[:60]}'")
    if name is not None:
        raise SystemExit(f"cli_suite.py: {path}: case '{name}' has no 'end'")
    return cases


def parse(args):
    spec = {"exit": "0", "stdout": [], "no-stdout": [], "stderr": [], "stderr-lines": None,
            "absent": [], "exists": [], "keep": []}
    i = 0
    while i < len(args) and args[i] != "--":
        option = args[i]
        if option not in OPTIONS_WITH_VALUE or i + 1 >= len(args):
            raise ValueError(f"unknown option or missing value: {option}")
        key, value = option[2:], args[i + 1]
        if isinstance(spec[key], list):
            spec[key].append(value)
        else:
            spec[key] = value
        i += 2
    if i >= len(args) - 1:
        raise ValueError("no command after --")
    return spec, args[i + 1:]


def sha256(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def lines_of(text):
    """The lines as grep sees them: split at newlines only (a progress bar's \\r is not an end)."""
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    return lines


def matches(pattern, lines):
    rx = re.compile(pattern)
    return any(rx.search(line) for line in lines)


def run_case(args):
    """Returns (list of failures, stdout, stderr, exit status)."""
    spec, command = parse(args)
    failures = []
    kept = {}
    for path in spec["keep"]:
        if not os.path.isfile(path):
            return [f"--keep {path} does not exist before the run"], "", "", None
        kept[path] = sha256(path)
    for path in spec["absent"]:
        if os.path.isdir(path) and not os.path.islink(path):
            subprocess.run(["rm", "-rf", path], check=True)
        elif os.path.lexists(path):
            os.remove(path)
    done = subprocess.run(command, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    code, out, err = done.returncode, done.stdout, done.stderr
    status = code if code >= 0 else 128 - code
    out = out.decode("utf-8", "replace")
    err = err.decode("utf-8", "replace")
    if spec["exit"] == "nonzero":
        if status == 0:
            failures.append("expected a non-zero exit status, got 0")
    elif status != int(spec["exit"]):
        failures.append(f"expected exit status {spec['exit']}, got {status}")
    out_lines, err_lines = lines_of(out), lines_of(err)
    for pattern in spec["stdout"]:
        if not matches(pattern, out_lines):
            failures.append(f"stdout does not match /{pattern}/")
    for pattern in spec["no-stdout"]:
        if matches(pattern, out_lines):
            failures.append(f"stdout must not match /{pattern}/")
    for pattern in spec["stderr"]:
        if not matches(pattern, err_lines):
            failures.append(f"stderr does not match /{pattern}/")
    if spec["stderr-lines"] is not None and err.count("\n") != int(spec["stderr-lines"]):
        failures.append(f"expected {spec['stderr-lines']} line(s) on stderr, got {err.count(chr(10))}")
    for path in spec["absent"]:
        if os.path.lexists(path):
            failures.append(f"{path} must not exist after the run")
    for path in spec["exists"]:
        if not os.path.lexists(path):
            failures.append(f"{path} was not written")
    for path, digest in kept.items():
        if not os.path.isfile(path) or sha256(path) != digest:
            failures.append(f"{path} was modified")
    # Only this file's own temporaries: other groups write next to it at the same time.
    for path in spec["absent"] + spec["exists"] + spec["keep"]:
        folder, base = os.path.split(path)
        prefix = "." + os.path.splitext(base)[0] + ".vdbhair-tmp-"
        try:
            left = [name for name in os.listdir(folder or ".") if name.startswith(prefix)]
        except OSError:
            left = []
        if left:
            failures.append(f"a temporary file of {path} was left in {folder}: {left[0]}")
    return failures, out, err, status


def main():
    if len(sys.argv) != 2:
        raise SystemExit("usage: cli_suite.py CASES_FILE")
    cases = read_cases(sys.argv[1])
    only = os.environ.get("VDBHAIR_CLI_CASES")
    if only:
        cases = [case for case in cases if re.search(only, case[0])]
    if not cases:
        raise SystemExit(f"cli_suite.py: {sys.argv[1]}: no case to run")
    failed = []
    for name, args in cases:
        start = time.monotonic()
        try:
            failures, out, err, status = run_case(args)
        except (ValueError, OSError, re.error) as e:
            failures, out, err, status = [f"the case cannot run: {e}"], "", "", None
        seconds = time.monotonic() - start
        if failures:
            failed.append(name)
            command = args[args.index("--") + 1:] if "--" in args else args
            print(f"FAIL: {name} ({seconds:.2f} s)")
            print(f"  $ {' '.join(command)}  (exit {status})")
            for failure in failures:
                print(f"  {failure}")
            print("  --- stdout:\n" + out + "  --- stderr:\n" + err, end="")
        else:
            print(f"ok   {name} ({seconds:.2f} s)")
        sys.stdout.flush()
    print(f"{len(cases) - len(failed)} of {len(cases)} cases passed")
    for name in failed:
        print(f"failed: {name}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
