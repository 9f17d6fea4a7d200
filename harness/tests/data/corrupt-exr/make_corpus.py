#!/usr/bin/env python3
"""Makes the corrupt EXR corpus from three valid 16x8 half RGBA plates
(scanline ZIP, scanline uncompressed, tiled ZIP) by byte surgery."""
import struct, sys, os, zlib

src, dst = sys.argv[1], sys.argv[2]
def rd(n): return bytearray(open(os.path.join(src, n), 'rb').read())

def attrs(b):
    """name -> (value offset, size); and the header's end (offset table start)."""
    out, i = {}, 8
    while b[i] != 0:
        n = b.index(b'\0', i); t = b.index(b'\0', n + 1)
        size = struct.unpack_from('<i', b, t + 1)[0]
        out[b[i:n].decode()] = (t + 5, size)
        i = t + 5 + size
    return out, i + 1

cases = {}
zipb, noneb, tiledb = rd('good-zip.exr'), rd('good-none.exr'), rd('good-tiled.exr')
za, zend = attrs(zipb); na, nend = attrs(noneb); ta, tend = attrs(tiledb)

def put(name, b): cases[name] = bytes(b)
def patched(b, off, fmt, *v):
    b = bytearray(b); struct.pack_into(fmt, b, off, *v); return b

put('empty.exr', b'')
put('magic-only.exr', zipb[:4])
put('bad-magic.exr', b'\x76\x2f\x31\x02'[::-1] + zipb[4:])
put('version-9.exr', patched(zipb, 4, '<B', 9))
put('header-cut.exr', zipb[:za['channels'][0] + 10])
put('attribute-size-huge.exr', patched(zipb, za['channels'][0] - 4, '<i', 0x7fffffff))
put('attribute-size-negative.exr', patched(zipb, za['channels'][0] - 4, '<i', -8))
put('compression-unknown.exr', patched(zipb, za['compression'][0], '<B', 99))
put('data-window-huge.exr', patched(zipb, za['dataWindow'][0], '<4i', 0, 0, 0x7ffffffe, 0x7ffffffe))
put('data-window-inverted.exr', patched(zipb, za['dataWindow'][0], '<4i', 15, 7, 0, 0))
put('data-window-32k.exr', patched(zipb, za['dataWindow'][0], '<4i', 0, 0, 32767, 32767))
put('display-window-huge.exr', patched(zipb, za['displayWindow'][0], '<4i', -2**31, -2**31, 2**31 - 1, 2**31 - 1))
put('no-channels.exr', patched(zipb, za['channels'][0], '<B', 0))
put('tile-size-zero.exr', patched(tiledb, ta['tiles'][0], '<2I', 0, 0))
put('tile-size-huge.exr', patched(tiledb, ta['tiles'][0], '<2I', 0x7fffffff, 0x7fffffff))
put('offset-past-end.exr', patched(noneb, nend + 8 * 3, '<Q', 10**9))
put('offset-max.exr', patched(noneb, nend + 8 * 3, '<Q', 2**64 - 1))
put('offset-into-header.exr', patched(noneb, nend + 8 * 3, '<Q', 8))
put('offsets-all-zero.exr', noneb[:nend] + bytes(8 * 8) + noneb[nend + 64:])
first = struct.unpack_from('<Q', noneb, nend)[0]
put('chunk-size-huge.exr', patched(noneb, first + 4, '<i', 0x7fffffff))
put('chunk-size-negative.exr', patched(noneb, first + 4, '<i', -1))
put('chunk-y-outside.exr', patched(noneb, first, '<i', 1000))
zfirst = struct.unpack_from('<Q', zipb, zend)[0]
b = bytearray(zipb)
for k in range(zfirst + 8, len(b)): b[k] ^= 0x5a
put('zip-stream-garbage.exr', b)
put('pixels-cut.exr', noneb[:len(noneb) - 100])
put('offset-table-cut.exr', noneb[:nend + 20])

os.makedirs(dst, exist_ok=True)
for name, data in cases.items():
    open(os.path.join(dst, name), 'wb').write(data)
print(len(cases), 'files')
