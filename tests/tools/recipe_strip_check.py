#!/usr/bin/env python3
"""Review tool for golden updates that add or change the recipe: strip the
recipe (PNG tEXt Software / iTXt frac:recipe chunks, comment lines, the VTK
title, the STL header) from each file of NEW and compare with OLD, byte for
byte. Usage: recipe_strip_check.py OLD_GOLDEN_DIR NEW_GOLDEN_DIR"""
import os, struct, sys, zlib

def strip_png(b):
    out = b[:8]; pos = 8
    while pos < len(b):
        n, = struct.unpack('>I', b[pos:pos+4]); t = b[pos+4:pos+8]
        data = b[pos+8:pos+8+n]
        chunk = b[pos:pos+12+n]
        assert zlib.crc32(t + data) == struct.unpack('>I', b[pos+8+n:pos+12+n])[0], 'crc'
        pos += 12 + n
        if t == b'tEXt' and data.startswith(b'Software\0'): continue
        if t == b'iTXt' and data.startswith(b'frac:recipe\0'): continue
        out += chunk
    return out

def strip_block(b):
    i = b.find(b'frac-recipe 1\n')
    if i < 0: return b
    ls = b.rfind(b'\n', 0, i) + 1
    prefix = b[ls:i]
    if prefix == b'':  # XML comment
        s = b.rfind(b'<!-- frac recipe\n', 0, i); e = b.find(b'-->\n', i) + 4
        return b[:s] + b[e:]
    pos = ls
    while True:
        nl = b.find(b'\n', pos)
        line = b[pos:nl]
        assert line.startswith(prefix)
        pos = nl + 1
        if line[len(prefix):].startswith(b'script:'): break
    return b[:ls] + b[pos:]

bad = 0
old, new = sys.argv[1], sys.argv[2]
for d in sorted(os.listdir(new)):
    for f in sorted(os.listdir(os.path.join(new, d))):
        nb = open(os.path.join(new, d, f), 'rb').read()
        ob = open(os.path.join(old, d, f), 'rb').read()
        ext = f.rsplit('.', 1)[-1]
        if ext == 'png': s = strip_png(nb)
        elif ext == 'vtk':
            nl = nb.split(b'\n'); ol = ob.split(b'\n'); nl[1] = ol[1]; s = b'\n'.join(nl)
        elif ext == 'stl': s = ob[:80] + nb[80:]
        else: s = strip_block(nb)
        ok = s == ob
        if not ok: bad += 1
        print(('same ' if ok else 'DIFF ') + d + '/' + f + (' (unchanged)' if nb == ob else ''))
print('bad', bad)
