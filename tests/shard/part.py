"""part.py — a reader of frac's part files, written from docs/scale.md ("The
part file"), independent of frac's C code: for the tests that look inside
parts (tests/shard/records.sh) and tools/shard_plan.sh.

    import part
    p = part.read(PATH)   # p['shard'], p['count'], p['records'], p['calls'], ...

Each record is a dict: call, section, op, kind, chunks, lo, hi, total, unit,
payload (bytes as stored). It checks the magic and the format version only;
the CRCs and the sums are format.sh's and merge's to check.
"""
import struct


def read(path):
    b = open(path, 'rb').read()
    pos = [0]

    def take(n):
        v = b[pos[0]:pos[0] + n]
        if len(v) != n:
            raise ValueError('%s: truncated' % path)
        pos[0] += n
        return v

    def u32():
        return struct.unpack('<I', take(4))[0]

    def u64():
        return struct.unpack('<Q', take(8))[0]

    def sstr():
        return take(u32())

    if take(8) != b'FRACPART' or u32() != 3:
        raise ValueError('%s: not a part file of format 3' % path)
    p = {'version': sstr().decode(), 'hash_name': sstr().decode(), 'hash': take(32), 'seed': u64()}
    p['frames'] = u32()
    p['frame'], p['first'], p['last'], p['step'] = struct.unpack('<4q', take(32))
    p['params'] = sstr().decode()
    p['shard'], p['count'] = u32(), u32()
    u32()  # header CRC
    p['records'] = []
    while True:
        mark = take(4)
        if mark == b'END ':
            break
        if mark != b'REC ':
            raise ValueError('%s: no record marker at byte %d' % (path, pos[0] - 4))
        r = {'call': u32(), 'section': u32(), 'op': u32(), 'kind': take(16).rstrip(b'\0').decode()}
        for k in ('chunks', 'lo', 'hi', 'total', 'unit'):
            r[k] = u64()
        r['payload'] = take(u64())
        u32()  # record CRC
        p['records'].append(r)
    u32()  # the number of records
    p['calls'] = u32()
    return p
