#!/usr/bin/env python3
"""Writes the lat-long environment map of examples/envmap: sky.hdr (64 x 32 texels,
Radiance RGBE, flat scanlines), the same texels as sky.exr (OpenEXR, HALF channels B, G, R,
ZIP compression; every value is an integer times a power of two that binary16 holds exactly)
and the tables a renderer builds from it for importance
sampling (pbrt-v4's PiecewiseConstant2D over the image, each texel weighted by sin of its
centre's theta): marginal.npy (the rows' CDF, H + 1 float32) and conditional.npy (each row's
CDF over its columns, H x (W + 1) float32), and prints the integral of the weighted
luminance over the unit square, which the sampler takes as p0. Standard library only.
Run from the repository root:  python3 examples/envmap/make.py
"""
import math
import os
import struct
import zlib

W, H = 64, 32
HERE = os.path.dirname(os.path.abspath(__file__))


def rgbe(i, j):
    """The texel (column i, row j from the top) as RGBE bytes: a sky brighter towards the
    horizon, and a sun of 2 x 2 texels 64 times brighter (exponent 142 against 136)."""
    theta = math.pi * (j + 0.5) / H
    phi = 2.0 * math.pi * (i + 0.5) / W - math.pi
    if j in (8, 9) and i in (42, 43):
        return (250, 230, 200, 142)
    sky = 0.5 + 0.5 * math.sin(theta) ** 4 + 0.2 * math.cos(3.0 * phi) * math.sin(theta)
    r, g, b = (int(40 + 100 * sky), int(60 + 110 * sky), int(80 + 130 * sky))
    return (r, g, b, 136)


def value(c, e):
    # the image crate's decoder: c * 2^(e - 136), exact in f32
    return c * 2.0 ** (e - 136)


def luminance(rgb):
    # Rec. 709 weights, as envmap.wgsl's env_luminance
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]


def npy(path, shape, values):
    header = "{'descr': '<f4', 'fortran_order': False, 'shape': %s, }" % (str(shape) if len(shape) > 1 else "(%d,)" % shape[0])
    header += " " * ((64 - (10 + len(header) + 1) % 64) % 64) + "\n"
    with open(path, "wb") as f:
        f.write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode("latin1"))
        f.write(struct.pack("<%df" % len(values), *values))


def exr_attribute(name, kind, value):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value


def exr_zip(raw):
    """OpenEXR's ZIP chunk: the bytes interleaved (even ones first, then odd), each stored as
    its difference from the one before plus 128, then zlib."""
    t = raw[0::2] + raw[1::2]
    diff = bytes([t[0]] + [(t[i] - t[i - 1] + 128) % 256 for i in range(1, len(t))])
    packed = zlib.compress(diff, 9)
    return packed if len(packed) < len(raw) else raw


def write_exr(path, texels):
    """A single-part scanline OpenEXR file (its layout as openexr.com's "OpenEXR File Layout"
    gives it): magic, version 2, the header's attributes, a null, the offset table, then
    chunks of 16 scanlines (y, size, the lines' B, G and R runs of HALF samples)."""
    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 1, 0, 1, 1) for c in "BGR") + b"\0"
    window = struct.pack("<4i", 0, 0, W - 1, H - 1)
    header = b"".join([
        exr_attribute("channels", "chlist", chlist),
        exr_attribute("compression", "compression", bytes([3])),
        exr_attribute("dataWindow", "box2i", window),
        exr_attribute("displayWindow", "box2i", window),
        exr_attribute("lineOrder", "lineOrder", bytes([0])),
        exr_attribute("pixelAspectRatio", "float", struct.pack("<f", 1.0)),
        exr_attribute("screenWindowCenter", "v2f", struct.pack("<2f", 0.0, 0.0)),
        exr_attribute("screenWindowWidth", "float", struct.pack("<f", 1.0)),
    ]) + b"\0"
    chunks = []
    for y in range(0, H, 16):
        raw = b"".join(struct.pack("<%de" % W, *[value(t[c], t[3]) for t in texels[j]]) for j in range(y, min(y + 16, H)) for c in (2, 1, 0))
        data = exr_zip(raw)
        chunks.append(struct.pack("<ii", y, len(data)) + data)
    start = 8 + len(header) + 8 * len(chunks)
    offsets = []
    for c in chunks:
        offsets.append(start)
        start += len(c)
    with open(path, "wb") as f:
        f.write(bytes([0x76, 0x2F, 0x31, 0x01]) + struct.pack("<I", 2) + header)
        f.write(struct.pack("<%dQ" % len(offsets), *offsets) + b"".join(chunks))


def main():
    texels = [[rgbe(i, j) for i in range(W)] for j in range(H)]
    with open(os.path.join(HERE, "sky.hdr"), "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (H, W))
        for row in texels:
            f.write(bytes(v for t in row for v in t))
    write_exr(os.path.join(HERE, "sky.exr"), texels)
    func = [[luminance([value(c, t[3]) for c in t[:3]]) * math.sin(math.pi * (j + 0.5) / H) for t in row] for j, row in enumerate(texels)]
    conditional, rows = [], []
    for row in func:
        total = sum(row)
        cdf, acc = [0.0], 0.0
        for f in row:
            acc += f
            cdf.append(acc / total)
        cdf[-1] = 1.0
        conditional += cdf
        rows.append(total / W)
    marginal, acc = [0.0], 0.0
    for r in rows:
        acc += r
        marginal.append(acc / sum(rows))
    marginal[-1] = 1.0
    npy(os.path.join(HERE, "marginal.npy"), (H + 1,), marginal)
    npy(os.path.join(HERE, "conditional.npy"), (H, W + 1), conditional)
    print("integral of the weighted luminance over the unit square (p0): %.9g" % (sum(rows) / H))


if __name__ == "__main__":
    main()
