#!/usr/bin/env python3
"""Runs one group of command-line test cases: one CTest per group.

    cli_suite.py [--in-process RUNNER --program VDBHAIR] CASES_FILE

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

Each command runs with standard input from /dev/null and its standard output and error captured.
Without --in-process every command is a process of its own. With it, a command that is the program
VDBHAIR itself runs in RUNNER (tests/apps/CliInProcess.cc: one process for the group, the same entry,
vdbhair::app::run, that VDBHAIR's main() calls), and the checks above are made the same way on its
status and output. A command stays a process of its own (separate_reason() says why) when
  - it is not VDBHAIR: a shell (sh -c, for pipes, several commands or a check of the output) or
    another program (python3, script, env, vdb_print);
  - an argument is '-': standard input or output as a file, which the group's one process shares;
  - its verb is batch: batch starts its own executable (/proc/self/exe) for each input and records
    what the processes it waits for used; in RUNNER it would start and measure RUNNER.
A runner that crashes ends its case as the process would have (128 + the signal) and a new one takes
the next case; one that reports state a new process would not have (a signal's flag, another working
folder) is replaced too. VDBHAIR_CLI_IN_PROCESS=0 in the environment runs every command as a process.
"""
import hashlib
import json
import os
import re
import select
import shutil
import subprocess
import sys
import tempfile
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


def exit_status(code):
    """The status as a shell reports it: a process ended by signal N is 128 + N."""
    return code if code >= 0 else 128 - code


def separate_reason(command, program):
    """Why COMMAND runs as a process of its own rather than in the in-process runner, or None."""
    if os.path.realpath(command[0]) != os.path.realpath(program):
        return "not the vdbhair program: a shell or another program"
    if "-" in command[1:]:
        return "'-' is standard input or output as a file"
    if len(command) > 1 and command[1] == "batch":
        return "batch starts its own executable for each input and measures those processes"
    return None


class InProcess:
    """The in-process runner (CliInProcess.cc): one process that runs command after command."""

    def __init__(self, path):
        self.path = path
        self.process = None
        self.folder = tempfile.mkdtemp(prefix="vdbhair-cli-")
        self.out = os.path.join(self.folder, "stdout")
        self.err = os.path.join(self.folder, "stderr")
        self.restarts = []
        self.signal = 0  # the signal that ended the runner in the last command, or 0

    def run(self, command, timeout=None):
        """Runs COMMAND (its argv); returns (exit status, stdout bytes, stderr bytes). After TIMEOUT
        seconds the runner is ended and subprocess.TimeoutExpired raised, as subprocess.run does."""
        for path in (self.out, self.err):
            if os.path.lexists(path):
                os.remove(path)
        if self.process is None:
            # Its own diagnostics (not a command's) go to this script's stderr, in CTest's log.
            self.process = subprocess.Popen([self.path, "--serve"], stdin=subprocess.PIPE, stdout=subprocess.PIPE)
        request = json.dumps({"argv": command, "stdout": self.out, "stderr": self.err}) + "\n"
        self.signal = 0
        try:
            self.process.stdin.write(request.encode("utf-8"))
            self.process.stdin.flush()
            if timeout is not None and not select.select([self.process.stdout], [], [], timeout)[0]:
                self.process.kill()
                self.process.wait()
                self.process = None
                raise subprocess.TimeoutExpired(command, timeout)
            line = self.process.stdout.readline()
        except BrokenPipeError:
            line = b""
        if line:
            answer = json.loads(line)
            if answer["status"] is None:
                raise OSError(f"the in-process runner cannot run it: {answer['why']}")
            status = answer["status"]
            if not answer["clean"]:
                self.restarts.append(answer["why"])
                self.close()
        else:  # the runner ended in the command (a crash, an uncaught exception): as the process would
            code = self.process.wait()
            status, self.signal = exit_status(code), max(0, -code)
            self.restarts.append(f"it ended with status {status}")
            self.process = None
        return status, self.read(self.out), self.read(self.err)

    @staticmethod
    def read(path):
        try:
            with open(path, "rb") as f:
                return f.read()
        except FileNotFoundError:
            return b""

    def close(self):
        if self.process is not None:
            self.process.stdin.close()
            self.process.wait()
            self.process = None

    def remove(self):
        self.close()
        shutil.rmtree(self.folder, ignore_errors=True)


def run_case(args, runner=None):
    """Runs the case, in RUNNER (an InProcess) if given; returns (list of failures, stdout,
    stderr, exit status)."""
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
    if runner is not None:
        status, out, err = runner.run(command)
    else:
        done = subprocess.run(command, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        status, out, err = exit_status(done.returncode), done.stdout, done.stderr
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
    argv = sys.argv[1:]
    runner_path = program = None
    while len(argv) > 2 and argv[0] in ("--in-process", "--program"):
        if argv[0] == "--in-process":
            runner_path = argv[1]
        else:
            program = argv[1]
        argv = argv[2:]
    if len(argv) != 1 or (runner_path is None) != (program is None):
        raise SystemExit("usage: cli_suite.py [--in-process RUNNER --program VDBHAIR] CASES_FILE")
    cases = read_cases(argv[0])
    only = os.environ.get("VDBHAIR_CLI_CASES")
    if only:
        cases = [case for case in cases if re.search(only, case[0])]
    if not cases:
        raise SystemExit(f"cli_suite.py: {argv[0]}: no case to run")
    if os.environ.get("VDBHAIR_CLI_IN_PROCESS") == "0":
        runner_path = None
    runner = InProcess(runner_path) if runner_path else None
    failed, in_process = [], 0
    try:
        for name, args in cases:
            start = time.monotonic()
            where = ""
            try:
                use = None
                if runner is not None:
                    reason = separate_reason(parse(args)[1], program)
                    use = runner if reason is None else None
                    where = ", in-process" if reason is None else f", a process: {reason}"
                    in_process += reason is None
                failures, out, err, status = run_case(args, use)
            except (ValueError, OSError, re.error) as e:
                failures, out, err, status = [f"the case cannot run: {e}"], "", "", None
            seconds = time.monotonic() - start
            if failures:
                failed.append(name)
                command = args[args.index("--") + 1:] if "--" in args else args
                print(f"FAIL: {name} ({seconds:.2f} s{where})")
                print(f"  $ {' '.join(command)}  (exit {status})")
                for failure in failures:
                    print(f"  {failure}")
                print("  --- stdout:\n" + out + "  --- stderr:\n" + err, end="")
            else:
                print(f"ok   {name} ({seconds:.2f} s{where})")
            sys.stdout.flush()
    finally:
        if runner is not None:
            runner.remove()
    print(f"{len(cases) - len(failed)} of {len(cases)} cases passed"
          + (f" ({in_process} in-process)" if runner is not None else ""))
    if runner is not None and runner.restarts:
        print("the in-process runner was replaced after a case: " + "; ".join(runner.restarts))
    for name in failed:
        print(f"failed: {name}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
