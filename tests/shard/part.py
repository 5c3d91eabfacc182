"""part.py — a reader of frac's part files that shares no code with frac:
the format of docs/scale.md "The part file" read with struct and zlib's
CRC-32, for the python3 parts of tests/shard/format.sh, share.sh,
records.sh and sums.sh, and of tools/shard_plan.sh; sums() and
sums_bytes() decode and encode a sums payload.

    PYTHONPATH=tests/shard python3 -c 'import part; p = part.read(PATH)'

read() walks the header, every record and the end, and checks only what
belongs to the framing: the magic, the markers, every CRC-32, that no field
runs past the end of the file, that the end counts the records and that
nothing follows it. What the fields must hold (the format number, the
script's hash, the chunk ranges) is for the caller to check. Records are
read as they come, however many and of whatever op or kind.
"""
import struct
import zlib
from types import SimpleNamespace

FORMAT = 4  # the format number docs/scale.md gives; the scripts check parts carry it


class Bytes:
    """A cursor over a file's bytes: take(n), u32(), u64(), i64(), sstr()."""

    def __init__(self, b):
        self.b = b
        self.pos = 0

    def take(self, n):
        v = self.b[self.pos:self.pos + n]
        assert len(v) == n, 'truncated at byte %d' % self.pos
        self.pos += n
        return v

    def u32(self):
        return struct.unpack('<I', self.take(4))[0]

    def u64(self):
        return struct.unpack('<Q', self.take(8))[0]

    def i64(self):
        return struct.unpack('<q', self.take(8))[0]

    def sstr(self):
        return self.take(self.u32())

    def crc(self, start, what):
        """Reads a CRC-32 and checks it against the bytes from start to here."""
        end = self.pos
        assert self.u32() == zlib.crc32(self.b[start:end]), what + ' CRC'


def read(path):
    """The part file at path as a namespace: the header's fields, records (a
    list, each with its fields, its payload and the offsets start and at of
    its marker and payload) and the end's records, calls and files."""
    c = Bytes(open(path, 'rb').read())
    assert c.take(8) == b'FRACPART', 'not a part file'
    p = SimpleNamespace()
    p.format = c.u32()
    p.version = c.sstr()
    p.hash_name = c.sstr()
    p.script_hash = c.take(32)
    p.seed = c.u64()
    p.frames = c.u32()
    p.frame = tuple(c.i64() for k in range(4))  # frame, first, last, step
    p.params = c.sstr()
    p.index, p.count = c.u32(), c.u32()
    c.crc(0, 'header')
    p.records = []
    while True:
        start = c.pos
        mark = c.take(4)
        if mark == b'END ':
            break
        assert mark == b'REC ', 'record marker at byte %d' % start
        r = SimpleNamespace(start=start)
        r.call, r.section, r.op = c.u32(), c.u32(), c.u32()
        r.kind = c.take(16).rstrip(b'\0').decode()
        r.chunks, r.lo, r.hi = c.u64(), c.u64(), c.u64()
        r.total, r.unit = c.u64(), c.u64()
        r.length = c.u64()
        r.at = c.pos
        r.payload = c.take(r.length)
        c.crc(start, 'record %d' % len(p.records))
        p.records.append(r)
    assert c.u32() == len(p.records), 'record count'
    p.calls = c.u32()
    p.files = [(c.sstr(), c.take(32)) for k in range(c.u32())]
    c.crc(start, 'end')
    assert c.pos == len(c.b), 'bytes after the end'
    return p


def leb128(payload):
    """The unsigned LEB128 numbers of a payload (7 bits a byte, low group
    first, the top bit set on every byte of a number but its last)."""
    vals, v, shift = [], 0, 0
    for byte in payload:
        v |= (byte & 0x7f) << shift
        shift += 7
        if not byte & 0x80:
            vals.append(v)
            v, shift = 0, 0
    assert shift == 0, 'a number runs past the payload'
    return vals


def sums(payload):
    """The values of a sums payload: LEB128 numbers, where a 0 is followed
    by the count of the further zeros of its run (format 4)."""
    nums, vals, k = leb128(payload), [], 0
    while k < len(nums):
        if nums[k]:
            vals.append(nums[k])
            k += 1
        else:
            assert k + 1 < len(nums), 'a zero without its run count'
            vals.extend([0] * (1 + nums[k + 1]))
            k += 2
    return vals


def leb128_bytes(v):
    """One number as unsigned LEB128."""
    out = bytearray()
    while v >= 0x80:
        out.append(v & 0x7f | 0x80)
        v >>= 7
    out.append(v)
    return bytes(out)


def sums_bytes(vals, longest=None):
    """vals as a sums payload: each run of zeros as 0 and the count of the
    zeros after the first, runs of at most longest zeros (None: whole runs)."""
    out, k = bytearray(), 0
    while k < len(vals):
        if vals[k]:
            out += leb128_bytes(vals[k])
            k += 1
            continue
        j = k
        while j < len(vals) and not vals[j] and (longest is None or j - k < longest):
            j += 1
        out += b'\0' + leb128_bytes(j - k - 1)
        k = j
    return bytes(out)
