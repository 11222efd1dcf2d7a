"""Run `vdbhair` command lines for the test runners (cli_suite.py, bad_inputs.py) through
vdbhair_forkserver (ForkServer.cc says why and how): each command runs vdbhair's main in a process
forked from a parent that has already loaded the program's libraries, which saves the 60 ms of
dynamic loading that is most of a short case's time.

    run(command, timeout=None) -> (return code, stdout bytes, stderr bytes)

The return code is subprocess's: the exit status, or -N for a signal N. A command is forked only when the
environment names the server (VDBHAIR_FORKSERVER) and the program (VDBHAIR_CLI), the command is
that program, its verb does not need an executable of its own (batch runs /proc/self/exe), no
argument holds a newline or a NUL, and VDBHAIR_CLI_EXEC is unset or 0; anything else is started
as a process of its own (subprocess). One server per thread, so the runners' worker threads do
not wait for each other.
"""
import atexit
import os
import select
import signal
import subprocess
import tempfile
import threading

SERVER = os.environ.get("VDBHAIR_FORKSERVER")
CLI = os.environ.get("VDBHAIR_CLI")
EXEC_ONLY = os.environ.get("VDBHAIR_CLI_EXEC", "0") not in ("", "0")
OWN_EXECUTABLE_VERBS = {"batch"}  # verbs that start the program itself (/proc/self/exe)

_local = threading.local()
_servers = []
_servers_lock = threading.Lock()


def _forkable(command):
    if EXEC_ONLY or not SERVER or not CLI or not os.path.isfile(SERVER):
        return False
    if not command or os.path.realpath(command[0]) != os.path.realpath(CLI):
        return False
    if len(command) > 1 and command[1] in OWN_EXECUTABLE_VERBS:
        return False
    return not any("\n" in a or "\0" in a for a in command)


def _server():
    s = getattr(_local, "server", None)
    if s is None:
        folder = tempfile.mkdtemp(prefix="vdbhair_forkrun_")
        proc = subprocess.Popen([SERVER], stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, bufsize=0)
        _local.pending = b""
        s = _local.server = (proc, os.path.join(folder, "stdout"), os.path.join(folder, "stderr"), folder)
        with _servers_lock:
            _servers.append(s)
    return s


@atexit.register
def _stop():
    for proc, out, err, folder in _servers:
        try:
            proc.stdin.close()
            proc.wait(timeout=10)
        except (OSError, subprocess.TimeoutExpired):
            proc.kill()
        for p in (out, err):
            if os.path.exists(p):
                os.remove(p)
        os.rmdir(folder)


def _reply(proc, kinds, timeout=None):
    """The server's next reply line, read from its pipe unbuffered (so that a time limit sees
    exactly what has arrived); TimeoutExpired if none is complete within @a timeout seconds."""
    fd = proc.stdout.fileno()
    buf = _local.pending
    while b"\n" not in buf:
        if timeout is not None and not select.select([fd], [], [], timeout)[0]:
            _local.pending = buf
            raise subprocess.TimeoutExpired("vdbhair_forkserver", timeout)
        chunk = os.read(fd, 4096)
        if not chunk:
            raise OSError("vdbhair_forkserver ended")
        buf += chunk
    line, _, _local.pending = buf.partition(b"\n")
    words = line.decode().split()
    if len(words) != 2 or words[0] not in kinds:
        raise OSError(f"vdbhair_forkserver: unexpected reply {words!r}")
    return words[0], int(words[1])


def run(command, timeout=None):
    """Run @a command (a list, the program first) with standard input from /dev/null."""
    if not _forkable(command):
        done = subprocess.run(command, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              timeout=timeout)
        return done.returncode, done.stdout, done.stderr
    proc, out, err, _ = _server()
    request = "\0".join([os.getcwd(), out, err] + list(command)) + "\n"
    data = request.encode("utf-8", "surrogateescape")
    while data:
        data = data[os.write(proc.stdin.fileno(), data):]

    _, pid = _reply(proc, ("pid",))
    try:
        kind, value = _reply(proc, ("exit", "signal"), timeout)
    except subprocess.TimeoutExpired:
        os.kill(pid, signal.SIGKILL)
        _reply(proc, ("exit", "signal"))
        raise subprocess.TimeoutExpired(command, timeout) from None
    status = value if kind == "exit" else -value
    with open(out, "rb") as f:
        stdout = f.read()
    with open(err, "rb") as f:
        stderr = f.read()
    return status, stdout, stderr
