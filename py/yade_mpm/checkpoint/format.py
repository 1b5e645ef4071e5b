"""The checkpoint file: magic, JSON header, NumPy payload with its checksum, and the build that wrote it.
Everything here reads or writes bytes; what goes into the arrays is serial.py's business."""
import hashlib
import io
import json
import os
import struct

import numpy as np

from .. import _core


# 5: the particles removed after leaving the grid (Solver.outside) and their account; 4: contact parameters (ContactParams.toDict) in the fingerprint; 3: named material options as words;
# 2: solver settings as Solver.settings() in the header (1: a hand-written list)
FORMAT = 5
MAGIC = b"YADE-MPM-CHECKPOINT\n"


class CheckpointError(ValueError):
    """A checkpoint that cannot be loaded into this scene (truncated, corrupted, other version or scene)."""


# ----------------------------------------------------------------------------------------- build id
_BUILD = None


def build_id():
    """Identity of the compiled core (SHA-256 of yade_mpm/_core*.so, 16 hex digits): a bitwise resume
    needs the same build, so a checkpoint records it and ``load`` refuses another one."""
    global _BUILD
    if _BUILD is None:
        h = hashlib.sha256()
        with open(_core.__file__, "rb") as f:
            for chunk in iter(lambda: f.read(1 << 20), b""):
                h.update(chunk)
        _BUILD = h.hexdigest()[:16]
    return _BUILD



def write(path, header, arrays):
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    payload = buf.getvalue()
    header["payload_bytes"] = len(payload)
    header["payload_sha256"] = hashlib.sha256(payload).hexdigest()
    hb = json.dumps(header).encode()
    tmp = f"{path}.tmp-{os.getpid()}"
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    try:
        with open(tmp, "wb") as f:
            f.write(MAGIC + struct.pack("<Q", len(hb)) + hb + payload)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:                                       # a failed write leaves no temporary file behind
        if os.path.exists(tmp):
            os.remove(tmp)
    return len(MAGIC) + 8 + len(hb) + len(payload)


# -------------------------------------------------------------------------------------------- load
def read(path, check_build=True):
    """(header, arrays) of a checkpoint file after checking magic, format, build (unless check_build is
    False: the caller checks it), length and checksum; raises CheckpointError naming the problem."""
    try:
        with open(path, "rb") as f:
            raw = f.read()
    except OSError as e:
        raise CheckpointError(f"checkpoint {path}: cannot read ({e.strerror})") from None
    if not raw.startswith(MAGIC):
        raise CheckpointError(f"checkpoint {path}: not a yade-mpm checkpoint (bad magic)")
    p = len(MAGIC)
    if len(raw) < p + 8:
        raise CheckpointError(f"checkpoint {path}: truncated ({len(raw)} bytes, header missing)")
    (hl,) = struct.unpack("<Q", raw[p:p + 8])
    if len(raw) < p + 8 + hl:
        raise CheckpointError(f"checkpoint {path}: truncated ({len(raw)} bytes, header incomplete)")
    try:
        header = json.loads(raw[p + 8:p + 8 + hl])
    except ValueError:
        header = None
    if not isinstance(header, dict):
        raise CheckpointError(f"checkpoint {path}: corrupted header (not a JSON object)")
    if header.get("format") != FORMAT:
        raise CheckpointError(f"checkpoint {path}: format version {header.get('format')}, this yade_mpm reads version {FORMAT} "
                              "only (checkpoints are not converted between formats: rerun from the start, or resume with the "
                              "yade_mpm version that wrote it)")
    if check_build:
        check_same_build(path, header)
    payload = raw[p + 8 + hl:]
    if len(payload) != header.get("payload_bytes"):
        raise CheckpointError(f"checkpoint {path}: truncated or padded (payload {len(payload)} bytes, "
                              f"expected {header.get('payload_bytes')})")
    if hashlib.sha256(payload).hexdigest() != header.get("payload_sha256"):
        raise CheckpointError(f"checkpoint {path}: corrupted (checksum mismatch)")
    with np.load(io.BytesIO(payload), allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    return header, arrays


def check_same_build(path, header):
    if header.get("build") != build_id():
        raise CheckpointError(f"checkpoint {path}: written by another build of the yade_mpm core ({header.get('build')}, "
                              f"this one is {build_id()}); a bitwise resume needs the same build — rerun from the start "
                              "or rebuild the version that wrote it")


def diff(a, b, prefix=""):
    """Human-readable differences between two fingerprints (saved a, here b)."""
    out = []
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            out += diff(a.get(k), b.get(k), f"{prefix}{k}.")
    elif a != b:
        sa, sb = json.dumps(a), json.dumps(b)
        cut = lambda s: s if len(s) < 120 else s[:117] + "..."
        out.append(f"{prefix[:-1] or 'value'}: checkpoint {cut(sa)}, this scene {cut(sb)}")
    return out

