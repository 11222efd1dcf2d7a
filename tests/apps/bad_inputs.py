#!/usr/bin/python3
"""The bad-input catalogue (issue 22): every case is a command that must fail, and each is run
twice - with a fresh output path and with an existing output. Each run must exit non-zero, print
exactly one line on stderr that names the file (or the verb or option at fault) and the rule
broken, leave no output and no temporary file, and leave an existing output byte-identical.
The cases run two at a time; each has a folder of its own for its output, so that what one case
leaves is checked after each of its runs, and the input folder and the whole output folder are
checked again once every case has run.

Usage: bad_inputs.py VDBHAIR WORKDIR [RUNNER]   (inputs are made here, small and synthetic)

With RUNNER (tests/apps/CliInProcess.cc), each command runs in-process, as cli_suite.py runs its
cases (a process start is most of such a case's time): one runner for each of the two at a time.
VDBHAIR_CLI_IN_PROCESS=0 in the environment runs every command as a process.
"""
import concurrent.futures
import math
import os
import shutil
import stat
import struct
import subprocess
import sys
import threading

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cli_suite import InProcess  # noqa: E402


CLI, WORK = sys.argv[1], sys.argv[2]
RUNNER = sys.argv[3] if len(sys.argv) > 3 and os.environ.get("VDBHAIR_CLI_IN_PROCESS") != "0" else None
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
IN = os.path.join(WORK, "in")
OUT = os.path.join(WORK, "out")
os.makedirs(IN)
os.makedirs(OUT)


def path(name):
    return os.path.join(IN, name)


def write(name, data):
    p = path(name)
    with open(p, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())
    return p


def hair(strands, header=None, segments=True):
    """cyHair bytes for a list of strands (lists of (x, y, z))."""
    pts = [p for s in strands for p in s]
    arrays = 2 | (1 if segments else 0)
    nS, nP, defseg = len(strands), len(pts), (len(strands[0]) - 1 if strands else 0)
    if header:
        nS, nP, arrays, defseg = header
    b = b"HAIR" + struct.pack("<4I", nS, nP, arrays, defseg) + struct.pack("<5f", 1, 0, .5, .5, .5) + bytes(88)
    if arrays & 1:
        b += b"".join(struct.pack("<H", len(s) - 1) for s in strands)
    b += b"".join(struct.pack("<3f", *p) for p in pts)
    return b


def data(strands):
    b = struct.pack("<i", len(strands))
    for s in strands:
        b += struct.pack("<i", len(s)) + b"".join(struct.pack("<3f", *p) for p in s)
    return b


def npy(shape, payload=b"", descr="<f4"):
    h = "{'descr': '%s', 'fortran_order': False, 'shape': %s, }" % (descr, shape)
    while (10 + len(h) + 1) % 64:
        h += " "
    h += "\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(h)) + h.encode() + payload


def tfx4(nS, nV, size=160):
    b = struct.pack("<f4I", 4.0, nS, nV, 160, 0) + bytes(4) + struct.pack("<I", 0)
    return b + bytes(size - len(b))


GOOD = [[(0, 0, 0), (0, 1, 0), (0, 2, 1)], [(1, 0, 0), (1, 1, 0), (1, 2, 0.5)]]
ZERO = [[(3, 3, 3)] * 4, [(5, 5, 5)] * 2]
good_hair = write("good.hair", hair(GOOD))
write("zero.hair", hair(ZERO))
write("somezero.hair", hair(GOOD + [[(7, 7, 7)] * 3]))
write("short1.hair", hair(GOOD + [[(1, 1, 1)]]))
setup = [subprocess.Popen([CLI, "convert", good_hair, path("good.vdb"), "-q"]),
         subprocess.Popen([CLI, "field", good_hair, "-o", path("field.vdb"), "-q"])]
if any(p.wait() != 0 for p in setup):
    sys.exit("the inputs good.vdb and field.vdb could not be made")
vdb = open(path("good.vdb"), "rb").read()


def fuzz_input(name):
    """A committed fuzzer finding, as bytes."""
    with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "io", "data", name), "rb") as f:
        return f.read()


def patched(b, at, fmt, value):
    b = bytearray(b)
    struct.pack_into(fmt, b, at, value)
    return bytes(b)


# Grid descriptor of good.vdb: name, type and parent strings after the grid count at byte 61.
desc = 65
for _ in range(3):
    desc += 4 + struct.unpack_from("<I", vdb, desc)[0]

ply_head = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
ply_strand = "element strand 1\nproperty ushort nsegs\nend_header\n"
scene = '{"vdbhair": "scene/1", "seed": 1, "step": 0.01, "guides": [%s]}'
deep = '{"vdbhair": "scene/1", "guides": [{"fit": ' + "[" * 200000 + "]" * 200000 + "}]}"
os.mkdir(path("folder.hair"))
os.mkdir(path("folder"))
os.mkfifo(path("pipe.hair"))

# (name, argv, words that must be in the one stderr line, output extension)
CASES = [
    # cyHair
    ("hair: empty", ["info", write("empty.hair", b"")], ["empty.hair", "not a cyHair file"]),
    ("hair: wrong magic", ["convert", write("magic.hair", b"HAIX" + hair(GOOD)[4:]), "{out}.obj"], ["magic.hair", "first 4 bytes must be \"HAIR\""]),
    ("hair: truncated header", ["convert", write("trunch.hair", hair(GOOD)[:60]), "{out}.obj"], ["trunch.hair", "shorter than the 128-byte cyHair header"]),
    ("hair: truncated body", ["convert", write("truncb.hair", hair(GOOD)[:-7]), "{out}.obj"], ["truncb.hair", "bytes, but the file has only"]),
    ("hair: 2^31-1 points", ["convert", write("hugep.hair", hair(GOOD, (2, 0x7fffffff, 3, 0))), "{out}.obj"], ["hugep.hair", "2147483647 points, which need"]),
    ("hair: 2^32-1 strands of 0 points", ["convert", write("nS.hair", hair([], (0xffffffff, 0, 2, 0))), "{out}.obj"], ["nS.hair", "4294967295 strands but only 0 points"]),
    ("hair: NaN coordinate", ["convert", write("nan.hair", hair([[(0, 0, 0), (math.nan, 1, 0)]])), "{out}.obj"], ["nan.hair", "non-finite coordinate"]),
    ("hair: unknown array bits", ["info", write("bits.hair", hair(GOOD, (2, 6, 64 | 2, 2)))], ["bits.hair", "unknown bits"]),
    ("hair: 1-vertex strand with --strict", ["convert", path("short1.hair"), "{out}.obj", "--strict"], ["short1.hair", "a strand needs at least 2"]),
    ("demo --strict: a 1-vertex strand (the reading options' --strict)", ["demo", path("short1.hair"), "-o", "{out}", "--strict"], ["short1.hair", "a strand needs at least 2"]),
    # USC-HairSalon .data
    ("data: empty", ["convert", write("empty.data", b""), "{out}.obj"], ["empty.data", "strand count needs 1 x 4 bytes"]),
    ("data: negative strand count", ["convert", write("neg.data", struct.pack("<i", -5)), "{out}.obj"], ["neg.data", "strand count -5 is negative"]),
    ("data: 2^31-1 strands", ["convert", write("huge.data", struct.pack("<i", 0x7fffffff) + bytes(8)), "{out}.obj"], ["huge.data", "2147483647 strands needs"]),
    ("data: negative vertex count", ["convert", write("negv.data", struct.pack("<ii", 1, -3)), "{out}.obj"], ["negv.data", "counts must not be negative"]),
    ("data: truncated vertices", ["convert", write("truncv.data", data(GOOD)[:-5]), "{out}.obj"], ["truncv.data", "bytes remain"]),
    ("data: Inf coordinate", ["convert", write("inf.data", data([[(0, 0, 0), (math.inf, 0, 0)]])), "{out}.obj"], ["inf.data", "non-finite coordinate"]),
    # PLY
    ("ply: wrong magic", ["convert", write("magic.ply", "plx\n"), "{out}.obj"], ["magic.ply", "not a PLY file"]),
    ("ply: no end_header", ["convert", write("noend.ply", ply_head), "{out}.obj"], ["noend.ply", "no 'end_header'"]),
    ("ply: big endian", ["convert", write("be.ply", "ply\nformat binary_big_endian 1.0\nend_header\n"), "{out}.obj"], ["be.ply", "binary_big_endian PLY is not supported"]),
    ("ply: negative element count", ["convert", write("negel.ply", "ply\nformat ascii 1.0\nelement vertex -2\nend_header\n"), "{out}.obj"], ["negel.ply", "negative count"]),
    ("ply: binary vertex count beyond the file", ["convert", write("bigv.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\n" + ply_strand + "\0" * 30), "{out}.obj"], ["bigv.ply", "declares 4000000000 items"]),
    ("ply: 2^63-1 items without properties, then a bad nsegs", ["convert", write("junk.ply", b"ply\nformat binary_little_endian 1.0\nelement junk 9223372036854775807\n" + ply_head.split("1.0\n", 1)[1].encode() + ply_strand.encode() + bytes(24) + struct.pack("<H", 5)), "{out}.obj"], ["junk.ply", "nsegs + 1 add up to 6 vertices but the 'vertex' element has 2"]),
    ("ply: nsegs sum wrapping 2^64", ["convert", write("wrap.ply", ply_head + "element strand 2\nproperty double nsegs\nend_header\n0 0 0\n1 1 1\n9223372036854775808\n9223372036854775808\n"), "{out}.obj"], ["wrap.ply", "add up to more than 2^64-1 vertices"]),
    ("ply: NaN coordinate", ["convert", write("nan.ply", ply_head + ply_strand + "0 0 0\n1 nan 1\n1\n"), "{out}.obj"], ["nan.ply", "non-finite coordinate"]),
    # TressFX
    ("tfx: 2^32-1 strands of 0 vertices", ["convert", write("zero.tfx", tfx4(0xffffffff, 0)), "{out}.obj"], ["zero.tfx", "4294967295 strands of 0 vertices"]),
    ("tfx: counts beyond the file", ["convert", write("big.tfx", tfx4(10, 4, 224)), "{out}.obj"], ["big.tfx", "10 strands of 4 vertices needs"]),
    ("tfx: unsupported version", ["convert", write("v9.tfx", struct.pack("<f", 9.5) + bytes(300)), "{out}.obj"], ["v9.tfx", "is not supported"]),
    ("tfx: ASCII strand count mismatch", ["convert", write("a.tfx", "version 2.0\nnumStrands 2\nstrand 0 numVerts 2 texcoord 0 0\n0 0 0\n1 1 1\n"), "{out}.obj"], ["a.tfx", "numStrands declares 2 strands but the file has 1"]),
    # HairNet convdata
    ("convdata: wrong magic", ["convert", write("magic.convdata", b"NUMPY" + bytes(20)), "{out}.obj"], ["magic.convdata", "not a NumPy .npy file"]),
    ("convdata: shape product wrapping 2^64", ["convert", write("wrap.convdata", npy("(4611686018427387904, 4, 1)", bytes(64))), "{out}.obj"], ["wrap.convdata", "floats, more than 2^64 bytes"]),
    ("convdata: dimension beyond 2^64", ["convert", write("dim.convdata", npy("(99999999999999999999999, 1, 1)", bytes(16))), "{out}.obj"], ["dim.convdata", "beyond 2^64-1"]),
    ("convdata: float64", ["convert", write("f8.convdata", npy("(4, 1, 1)", bytes(32), "<f8")), "{out}.obj"], ["f8.convdata", "dtype '<f8' is not supported"]),
    # Alembic (Ogawa): the header's root offset and a group's child count are bounded by the file
    ("abc: HDF5 archive, not Ogawa", ["convert", write("hdf5.abc", b"\x89HDF\r\n\x1a\n" + bytes(40)), "{out}.obj"], ["hdf5.abc", "no \"Ogawa\" magic"]),
    ("abc: root group past the end", ["convert", write("root.abc", b"Ogawa\xff\x00\x01" + struct.pack("<Q", 1 << 40) + bytes(16)), "{out}.obj"], ["root.abc", "at byte 8: root group offset 1099511627776 lies outside"]),
    ("abc: 2^60 children", ["convert", write("kids.abc", b"Ogawa\xff\x00\x01" + struct.pack("<QQ", 16, 1 << 60) + bytes(16)), "{out}.obj"], ["kids.abc", "at byte 16: archive root: group declares 1152921504606846976 children"]),
    # OBJ
    ("obj: index beyond the vertices", ["convert", write("idx.obj", "v 0 0 0\nv 1 1 1\nl 1 5\n"), "{out}.hair"], ["idx.obj", "5"]),
    ("obj: NaN vertex", ["convert", write("nan.obj", "v 0 0 0\nv nan 1 1\nl 1 2\n"), "{out}.hair"], ["nan.obj", "non-finite"]),
    # The long fuzz run's findings (tests/io/data, issue 22)
    ("usda: values nested 7,000 deep (fuzz_usda)", ["convert", write("nested.usda", fuzz_input("fuzz_usda_nested.usda")), "{out}.obj"], ["nested.usda", "line 5: values nested more than 128 deep"]),
    ("mesh: an ascii list count of 3.9e85 (fuzz_mesh)", ["scalp", write("listcount.ply", fuzz_input("fuzz_mesh_list_count.ply")), "-o", "{out}.vdb"], ["listcount.ply", "declares 3.88889e+85 items but fewer remain"]),
    ("usda: prims nested 200 deep", ["convert", write("prims.usda", "#usda 1.0\n" + 'def Xform "x" {\n' * 200 + "}" * 200 + "\n"), "{out}.obj"], ["prims.usda", "line 130: prims nested more than 128 deep"]),
    # VDB
    ("vdb: not a VDB file", ["convert", write("junk.vdb", "this is not a vdb file"), "{out}.obj"], ["junk.vdb", "not a readable VDB file"]),
    ("vdb: file metadata count beyond the file", ["convert", write("meta.vdb", patched(vdb, 57, "<I", 0xffffffff)), "{out}.obj"], ["meta.vdb", "metadata declares 4294967295 entries"]),
    ("vdb: grid count beyond the file", ["convert", write("count.vdb", patched(vdb, 61, "<I", 0x7fffffff)), "{out}.obj"], ["count.vdb", "declares 2147483647 grids"]),
    ("vdb: grid end beyond the file", ["convert", write("end.vdb", patched(vdb, desc + 16, "<q", len(vdb) + 1000)), "{out}.obj"], ["end.vdb", "<= start <= data <= end <="]),
    ("vdb: truncated", ["convert", write("trunc.vdb", vdb[:len(vdb) // 2]), "{out}.obj"], ["trunc.vdb", "grid 0"]),
    ("vdb: no strands grid", ["convert", path("field.vdb"), "{out}.obj"], ["field.vdb", "no grid named 'strands'"]),
    ("vdb: wrong-type grid", ["convert", path("field.vdb"), "{out}.obj", "--grid", "density"], ["field.vdb", "not a PointDataGrid"]),
    # Scenes
    ("scene: nested 200,000 deep", ["grow", write("deep.json", deep), "-o", "{out}.hair"], ["deep.json", "guides[0].fit[0]", "at most 64 levels"]),
    ("scene: 1e400", ["grow", write("big.json", scene % '{"root": [0, 1e400, 0]}'), "-o", "{out}.hair"], ["big.json", "guides[0].root[1]", "1e400 is beyond the range of a double"]),
    ("scene: invalid JSON", ["grow", write("broken.json", '{"vdbhair": '), "-o", "{out}.hair"], ["broken.json", "not valid JSON"]),
    # Zero-length strands and parameters
    ("field: every strand of zero length", ["field", path("zero.hair"), "-o", "{out}.vdb"], ["zero.hair", "2 of 2 strands have zero length", "nothing to field"]),
    ("refine: every strand of zero length", ["refine", path("zero.hair"), "-o", "{out}.hair"], ["zero.hair", "zero length", "nothing to refine"]),
    ("field --strict: one strand of zero length", ["field", path("somezero.hair"), "-o", "{out}.vdb", "--strict"], ["somezero.hair", "1 of 3 strands have zero length (strand 2", "--strict rejects them"]),
    ("retrace --strict: one strand of zero length", ["retrace", path("somezero.hair"), "--field", path("field.vdb"), "-o", "{out}.hair", "--strict"], ["somezero.hair", "zero length", "--strict"]),
    ("field: negative voxel size", ["field", good_hair, "-o", "{out}.vdb", "--voxel-size", "-1"], ["voxel", "-1"]),
    ("refine: negative step", ["refine", good_hair, "-o", "{out}.hair", "--step", "-0.5"], ["--step -0.5", "must be at least 0 world units"]),
    # Paths and the command line
    ("info: a directory", ["info", path("folder")], ["folder", "is a directory, not a regular file"]),
    ("info: a directory with a strand extension", ["info", path("folder.hair")], ["folder.hair", "is a directory"]),
    ("info: a FIFO", ["info", path("pipe.hair")], ["pipe.hair", "is a FIFO (named pipe), not a regular file"]),
    ("convert: missing input", ["convert", path("missing.hair"), "{out}.obj"], ["missing.hair", "No such file or directory"]),
    ("convert: unknown input extension", ["convert", write("x.xyz", "1 2 3\n"), "{out}.obj"], ["x.xyz", "unknown strand format '.xyz'"]),
    ("convert: unknown output extension", ["convert", good_hair, "{out}.xyz"], [".xyz", "unknown strand format"]),
    ("convert: read-only output format", ["convert", good_hair, "{out}.tfx"], [".tfx", "read-only"]),
    ("convert: output in a missing folder", ["convert", good_hair, os.path.join(OUT, "nofolder", "x.obj")], ["nofolder", "does not exist"]),
    ("convert: --threads -1", ["convert", good_hair, "{out}.obj", "--threads", "-1"], ["--threads -1", "must be at least 0"]),
    ("a missing required option is one line", ["retrace", good_hair, "-o", "{out}.hair"], ["vdbhair retrace: --field is required (run 'vdbhair retrace --help' for usage)"]),
    ("an unknown verb gets the closest", ["feild", good_hair, "-o", "{out}.vdb"], ["unknown verb 'feild'", "did you mean field?"]),
]


def temporaries(folder):
    return [os.path.join(d, f) for d, dirs, files in os.walk(folder) for f in dirs + files if ".vdbhair-tmp-" in f]


runners = []
local = threading.local()


def run(args):
    """Runs vdbhair with ARGS; returns (return code as subprocess gives it, stderr bytes)."""
    if RUNNER is None:
        done = subprocess.run([CLI] + args, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=60)
        return done.returncode, done.stderr
    if not hasattr(local, "runner"):
        local.runner = InProcess(RUNNER)
        runners.append(local.runner)
    status, _, err = local.runner.run([CLI] + args, timeout=60)
    return (-local.runner.signal if local.runner.signal else status), err


def run_case(i):
    """Both runs of case i; returns its failures."""
    name, argv, words = CASES[i]
    folder = os.path.join(OUT, "case%02d" % i)
    os.makedirs(folder)
    out = os.path.join(folder, "out")
    failures = []
    for existing in (False, True):
        args = [a.replace("{out}", out) for a in argv]
        outputs = [a for a in args if a.startswith(out)]
        sentinel = b"existing output %d\n" % i
        for o in outputs:
            if os.path.exists(o):
                os.remove(o)
            if existing:
                with open(o, "wb") as f:
                    f.write(sentinel)
        try:
            returncode, stderr = run(args)
        except subprocess.TimeoutExpired:
            failures.append("%s: still running after 60 s" % name)
            continue
        err = stderr.decode(errors="replace")
        lines = err.splitlines()
        what = "%s (%s output)" % (name, "existing" if existing else "no")
        if returncode == 0:
            failures.append("%s: exit status 0" % what)
        if returncode < 0:
            failures.append("%s: killed by signal %d" % (what, -returncode))
        if len(lines) != 1:
            failures.append("%s: %d stderr lines: %r" % (what, len(lines), err[:600]))
        elif not lines[0].startswith("vdbhair"):
            failures.append("%s: stderr does not start with 'vdbhair': %r" % (what, lines[0]))
        for w in words:
            if w not in err:
                failures.append("%s: stderr lacks %r: %r" % (what, w, err[:600]))
        for o in outputs:
            if existing:
                if not os.path.exists(o) or open(o, "rb").read() != sentinel:
                    failures.append("%s: the existing output %s was changed" % (what, o))
            elif os.path.exists(o):
                failures.append("%s: an output %s was written" % (what, o))
        if temporaries(folder):
            failures.append("%s: temporary files left: %s" % (what, temporaries(folder)))
    return failures


failures = []
with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
    for (name, _, _), fs in zip(CASES, pool.map(run_case, range(len(CASES)))):
        print("ok " if not fs else "BAD", name)
        failures += fs
for runner in runners:
    runner.remove()
# Every run has ended: nothing of theirs may be left anywhere (a case's own folder was checked
# after each of its runs; this covers the inputs' folder and the rest).
for f in temporaries(IN) + temporaries(OUT):
    failures.append("temporary file left after all cases: %s" % f)

print("%d cases, %d runs, %d failures" % (len(CASES), 2 * len(CASES), len(failures)))
for f in failures:
    print("FAIL:", f)
sys.exit(1 if failures else 0)
