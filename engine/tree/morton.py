"""Morton keys and their radix sort: the particles ordered along a Z-order curve.

A particle's key interleaves the bits of its integer coordinates in the bounding cube of all
particles (Morton 1966, "A computer oriented geodetic data base and a new technique in file
sequencing", IBM report): 21 bits per axis in 3-D (a 63-bit key), 31 in 2-D (62 bits). Bits
``[level * dim, (level + 1) * dim)`` from the bottom are the child a particle falls in at the
``level``-th subdivision counted from the finest, so sorting by key puts every cell of the
octree (quadtree) on a contiguous range. The sort is a least-significant-digit radix sort of
(key, slot) pairs, 11 bits a pass: linear in n, stable, and it allocates nothing.
"""
from ..cache import jit

from .layout import RADIX, RADIX_BITS


@jit(error_model="numpy", inline="always")
def bits_per_axis(dim):
    return 21 if dim == 3 else 31


@jit(error_model="numpy", inline="always")
def spread3(v):
    """The 21 low bits of v, two zeros inserted after each (bit k moves to 3k)."""
    v &= 0x1FFFFF
    v = (v | (v << 32)) & 0x1F00000000FFFF
    v = (v | (v << 16)) & 0x1F0000FF0000FF
    v = (v | (v << 8)) & 0x100F00F00F00F00F
    v = (v | (v << 4)) & 0x10C30C30C30C30C3
    v = (v | (v << 2)) & 0x1249249249249249
    return v


@jit(error_model="numpy", inline="always")
def spread2(v):
    """The 31 low bits of v, a zero inserted after each (bit k moves to 2k)."""
    v &= 0x7FFFFFFF
    v = (v | (v << 16)) & 0x0000FFFF0000FFFF
    v = (v | (v << 8)) & 0x00FF00FF00FF00FF
    v = (v | (v << 4)) & 0x0F0F0F0F0F0F0F0F
    v = (v | (v << 2)) & 0x3333333333333333
    v = (v | (v << 1)) & 0x5555555555555555
    return v


@jit(error_model="numpy", inline="always")
def cell_index(x, lo, scale, top):
    """The integer coordinate of x in [lo, lo + side): floor((x - lo) scale), clipped to
    [0, top] (scale = 2^bits / side; the clip keeps the cube's far face inside), clipped as a
    float first, so that no infinite or NaN value is ever converted to an integer."""
    f = (x - lo) * scale
    if not f > 0.0:
        return 0
    if f >= top:
        return top
    return int(f)


@jit(error_model="numpy", inline="always")
def bounding_cube(pos, slots, m, dim):
    """(lo_x, lo_y, lo_z, side) of a cube holding the m particles ``slots[:m]``: their
    bounding box's lower corner and its largest side (1.0 if they coincide, so that keys stay
    defined)."""
    i = slots[0]
    lx = hx = pos[0, i]
    ly = hy = pos[1, i]
    lz = hz = pos[2, i] if dim == 3 else 0.0
    for k in range(1, m):
        i = slots[k]
        lx = min(lx, pos[0, i])
        hx = max(hx, pos[0, i])
        ly = min(ly, pos[1, i])
        hy = max(hy, pos[1, i])
        if dim == 3:
            lz = min(lz, pos[2, i])
            hz = max(hz, pos[2, i])
    side = max(hx - lx, hy - ly, hz - lz)
    if side == 0.0:
        side = 1.0
    return lx, ly, lz, side


@jit(error_model="numpy", inline="always")
def keys(pos, slots, m, out):
    """out[k] = the Morton key of particle ``slots[k]``, k < m, in the particles' bounding
    cube."""
    dim = pos.shape[0]
    lx, ly, lz, side = bounding_cube(pos, slots, m, dim)
    bits = bits_per_axis(dim)
    top = (1 << bits) - 1
    scale = (1 << bits) / side
    if dim == 3:
        for k in range(m):
            i = slots[k]
            out[k] = (spread3(cell_index(pos[0, i], lx, scale, top))
                      | (spread3(cell_index(pos[1, i], ly, scale, top)) << 1)
                      | (spread3(cell_index(pos[2, i], lz, scale, top)) << 2))
    else:
        for k in range(m):
            i = slots[k]
            out[k] = (spread2(cell_index(pos[0, i], lx, scale, top))
                      | (spread2(cell_index(pos[1, i], ly, scale, top)) << 1))


@jit(error_model="numpy", inline="always")
def range_box(px, py, pz, s, e):
    """(lo x, y, z, hi x, y, z): the bounding box of sorted particles [s, e)."""
    lx = hx = px[s]
    ly = hy = py[s]
    lz = hz = pz[s]
    for k in range(s + 1, e):
        lx = min(lx, px[k])
        hx = max(hx, px[k])
        ly = min(ly, py[k])
        hy = max(hy, py[k])
        lz = min(lz, pz[k])
        hz = max(hz, pz[k])
    return lx, ly, lz, hx, hy, hz


@jit(error_model="numpy", inline="always")
def range_keys(px, py, pz, s, e, dim, out):
    """out[k] = the key of sorted particle k in [s, e), in the bounding cube of those
    particles alone; False (nothing written) if they all coincide."""
    lx, ly, lz, hx, hy, hz = range_box(px, py, pz, s, e)
    side = max(hx - lx, hy - ly, hz - lz)
    if not side > 0.0:
        return False
    bits = bits_per_axis(dim)
    top = (1 << bits) - 1
    scale = (1 << bits) / side
    for k in range(s, e):
        if dim == 3:
            out[k] = (spread3(cell_index(px[k], lx, scale, top))
                      | (spread3(cell_index(py[k], ly, scale, top)) << 1)
                      | (spread3(cell_index(pz[k], lz, scale, top)) << 2))
        else:
            out[k] = (spread2(cell_index(px[k], lx, scale, top))
                      | (spread2(cell_index(py[k], ly, scale, top)) << 1))
    return True


@jit(error_model="numpy", inline="always")
def _pass(keys, slots, keys_out, slots_out, m, shift, counts):
    """One stable counting-sort pass on the digit at ``shift``; False (nothing moved) when
    every key has the same digit there."""
    for d in range(RADIX + 1):
        counts[d] = 0
    for i in range(m):
        counts[((keys[i] >> shift) & (RADIX - 1)) + 1] += 1
    for d in range(RADIX):
        if counts[d + 1] == m:
            return False
    for d in range(RADIX):
        counts[d + 1] += counts[d]
    for i in range(m):
        d = (keys[i] >> shift) & (RADIX - 1)
        k = counts[d]
        keys_out[k] = keys[i]
        slots_out[k] = slots[i]
        counts[d] = k + 1
    return True


@jit(error_model="numpy", inline="always")
def sort(keys, slots, keys_tmp, slots_tmp, m, dim, counts):
    """Sort the pairs (keys[i], slots[i]), i < m, by key (stable); the result is in ``keys``
    and ``slots`` (the *_tmp arrays are scratch of the same size)."""
    total = dim * bits_per_axis(dim)
    in_tmp = False
    for shift in range(0, total, RADIX_BITS):
        if in_tmp:
            moved = _pass(keys_tmp, slots_tmp, keys, slots, m, shift, counts)
        else:
            moved = _pass(keys, slots, keys_tmp, slots_tmp, m, shift, counts)
        if moved:
            in_tmp = not in_tmp
    if in_tmp:
        for i in range(m):
            keys[i] = keys_tmp[i]
            slots[i] = slots_tmp[i]
