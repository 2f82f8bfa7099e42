"""Local expansions: the field of far cells expanded about a point z near its targets.

A local expansion about z holds, for the field f(z + x) = sum_j beta_j (p_j - z - x) /
|p_j - z - x|^3 of far sources, its value F, gradient G and second derivatives H at z,

    f_a(z + x) ~ F_a + G_ab x_b + H_abc x_b x_c

(F, G and H symmetric in their indices; H holds half the second derivatives), and for the
potential psi(z + x) = sum_j beta_j / |p_j - z - x| its value P0, gradient P1 and half its
Hessian P2. Three steps of a fast multipole method (Greengard & Rokhlin 1987, J. Comput.
Phys. 73, 325; Cartesian form: Dehnen 2002, J. Comput. Phys. 179, 27):

- M2L (``cells_to_local``): a cell's multipoles (``multipoles``: weight M, dipole D,
  quadrupole Q about its centre c, d = c - z) into F, G, H: F from M, D and Q; G from M and D;
  H from M: every term of total order 2 in (cell radius + |x|) / |d| relative to the
  monopole, so the truncation error is of third order, as that of the multipoles themselves;
- L2L (``shift_local``): the expansion moved from z to z + t, exactly (a quadratic in x is a
  quadratic about any point): F' = F + G t + H[t, t], G' = G + 2 H t, H' = H;
- L2P (``local_to_targets``): the quadratic evaluated at each target.

The entries of ``loc`` (``layout.LOCAL`` floats): 0-2 F (x, y, z), 3-8 G (xx, yy, zz, xy, xz,
yz), 9-18 H (xxx, yyy, zzz, xxy, xxz, xyy, yyz, xzz, yzz, xyz), 19 P0, 20-22 P1, 23-28 P2
(xx, yy, zz, xy, xz, yz).
"""
import math

from ..cache import jit

from . import multipoles as mp

#: the vectorising flags of ``engine.forces.pairwise`` (never 'nnan'/'ninf': NaN must survive)
SIMD_MATH = {"reassoc", "contract", "nsz", "arcp"}


@jit(fastmath=SIMD_MATH, error_model="numpy")
def cells_to_local(lc, count, zx, zy, zz, eps2, loc):
    """loc += the local expansion about z of the listed cells' fields (M2L; module
    ``multipoles``): loc[0:3] the field F, loc[3:9] its gradient G (xx, yy, zz, xy, xz, yz),
    loc[9:19] the second derivatives H (xxx, yyy, zzz, xxy, xxz, xyy, yyz, xzz, yzz, xyz)."""
    fx = fy = fz = 0.0
    gxx = gyy = gzz = gxy = gxz = gyz = 0.0
    hxxx = hyyy = hzzz = hxxy = hxxz = hxyy = hyyz = hxzz = hyzz = hxyz = 0.0
    for j in range(count):
        dx = lc[mp.CX, j] - zx
        dy = lc[mp.CY, j] - zy
        dz = lc[mp.CZ, j] - zz
        m = lc[mp.M, j]
        ex = lc[mp.DX, j]
        ey = lc[mp.DY, j]
        ez = lc[mp.DZ, j]
        qxx = lc[mp.QXX, j]
        qyy = lc[mp.QYY, j]
        qzz = lc[mp.QZZ, j]
        qxy = lc[mp.QXY, j]
        qxz = lc[mp.QXZ, j]
        qyz = lc[mp.QYZ, j]
        inv = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz + eps2)
        inv2 = inv * inv
        inv3 = inv * inv2
        inv5 = inv3 * inv2
        inv7 = inv5 * inv2
        dd = ex * dx + ey * dy + ez * dz
        qx = qxx * dx + qxy * dy + qxz * dz
        qy = qxy * dx + qyy * dy + qyz * dz
        qz = qxz * dx + qyz * dy + qzz * dz
        dqd = qx * dx + qy * dy + qz * dz
        trace = qxx + qyy + qzz
        common = m * inv3 - 3.0 * dd * inv5 + 7.5 * dqd * inv7 - 1.5 * trace * inv5
        fx += common * dx + inv3 * ex - 3.0 * inv5 * qx
        fy += common * dy + inv3 * ey - 3.0 * inv5 * qy
        fz += common * dz + inv3 * ez - 3.0 * inv5 * qz
        # G_kl = M g_kl + D_i g_ikl
        a = 3.0 * m * inv5 - 15.0 * dd * inv7
        b = m * inv3 - 3.0 * dd * inv5
        c3 = 3.0 * inv5
        gxx += a * dx * dx - b + c3 * 2.0 * ex * dx
        gyy += a * dy * dy - b + c3 * 2.0 * ey * dy
        gzz += a * dz * dz - b + c3 * 2.0 * ez * dz
        gxy += a * dx * dy + c3 * (ex * dy + ey * dx)
        gxz += a * dx * dz + c3 * (ex * dz + ez * dx)
        gyz += a * dy * dz + c3 * (ey * dz + ez * dy)
        # H_klm = -M g_klm / 2 = S d_k d_l d_m - T (delta_kl d_m + delta_km d_l + delta_lm d_k)
        s = 7.5 * m * inv7
        t = 1.5 * m * inv5
        hxxx += s * dx * dx * dx - 3.0 * t * dx
        hyyy += s * dy * dy * dy - 3.0 * t * dy
        hzzz += s * dz * dz * dz - 3.0 * t * dz
        hxxy += s * dx * dx * dy - t * dy
        hxxz += s * dx * dx * dz - t * dz
        hxyy += s * dx * dy * dy - t * dx
        hyyz += s * dy * dy * dz - t * dz
        hxzz += s * dx * dz * dz - t * dx
        hyzz += s * dy * dz * dz - t * dy
        hxyz += s * dx * dy * dz
    loc[0] += fx
    loc[1] += fy
    loc[2] += fz
    loc[3] += gxx
    loc[4] += gyy
    loc[5] += gzz
    loc[6] += gxy
    loc[7] += gxz
    loc[8] += gyz
    loc[9] += hxxx
    loc[10] += hyyy
    loc[11] += hzzz
    loc[12] += hxxy
    loc[13] += hxxz
    loc[14] += hxyy
    loc[15] += hyyz
    loc[16] += hxzz
    loc[17] += hyzz
    loc[18] += hxyz


@jit(fastmath=SIMD_MATH, error_model="numpy")
def cells_to_local_potential(lc, count, zx, zy, zz, eps2, loc):
    """loc[19:29] += the local expansion about z of the listed cells' potential: P0, P1
    (x, y, z), P2 (xx, yy, zz, xy, xz, yz), psi(z + delta) = P0 + P1.delta + delta.P2.delta."""
    p0 = 0.0
    px_ = py_ = pz_ = 0.0
    pxx = pyy = pzz = pxy = pxz = pyz = 0.0
    for j in range(count):
        dx = lc[mp.CX, j] - zx
        dy = lc[mp.CY, j] - zy
        dz = lc[mp.CZ, j] - zz
        m = lc[mp.M, j]
        ex = lc[mp.DX, j]
        ey = lc[mp.DY, j]
        ez = lc[mp.DZ, j]
        qxx = lc[mp.QXX, j]
        qyy = lc[mp.QYY, j]
        qzz = lc[mp.QZZ, j]
        qxy = lc[mp.QXY, j]
        qxz = lc[mp.QXZ, j]
        qyz = lc[mp.QYZ, j]
        inv = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz + eps2)
        inv2 = inv * inv
        inv3 = inv * inv2
        inv5 = inv3 * inv2
        dd = ex * dx + ey * dy + ez * dz
        dqd = (qxx * dx * dx + qyy * dy * dy + qzz * dz * dz
               + 2.0 * (qxy * dx * dy + qxz * dx * dz + qyz * dy * dz))
        trace = qxx + qyy + qzz
        p0 += m * inv - dd * inv3 + 1.5 * dqd * inv5 - 0.5 * trace * inv3
        # P1_l = M d_l / r^3 - 3 (D.d) d_l / r^5 + D_l / r^3
        u = m * inv3 - 3.0 * dd * inv5
        px_ += u * dx + ex * inv3
        py_ += u * dy + ey * inv3
        pz_ += u * dz + ez * inv3
        # P2_lm = M (3 d_l d_m / r^5 - delta_lm / r^3) / 2
        v = 1.5 * m * inv5
        w = 0.5 * m * inv3
        pxx += v * dx * dx - w
        pyy += v * dy * dy - w
        pzz += v * dz * dz - w
        pxy += v * dx * dy
        pxz += v * dx * dz
        pyz += v * dy * dz
    loc[19] += p0
    loc[20] += px_
    loc[21] += py_
    loc[22] += pz_
    loc[23] += pxx
    loc[24] += pyy
    loc[25] += pzz
    loc[26] += pxy
    loc[27] += pxz
    loc[28] += pyz


@jit(fastmath=SIMD_MATH, error_model="numpy")
def local_to_targets(px, py, pz, s, e, zx, zy, zz, loc, ax, ay, az, phi, potential):
    """Targets [s, e) += the local expansion about z (L2P)."""
    for i in range(s, e):
        x = px[i] - zx
        y = py[i] - zy
        z = pz[i] - zz
        xx = x * x
        yy = y * y
        zz2 = z * z
        xy = 2.0 * x * y
        xz = 2.0 * x * z
        yz = 2.0 * y * z
        ax[i] += (loc[0] + loc[3] * x + loc[6] * y + loc[7] * z
                  + loc[9] * xx + loc[14] * yy + loc[16] * zz2
                  + loc[12] * xy + loc[13] * xz + loc[18] * yz)
        ay[i] += (loc[1] + loc[6] * x + loc[4] * y + loc[8] * z
                  + loc[12] * xx + loc[10] * yy + loc[17] * zz2
                  + loc[14] * xy + loc[18] * xz + loc[15] * yz)
        az[i] += (loc[2] + loc[7] * x + loc[8] * y + loc[5] * z
                  + loc[13] * xx + loc[15] * yy + loc[11] * zz2
                  + loc[18] * xy + loc[16] * xz + loc[17] * yz)
        if potential:
            phi[i] += (loc[19] + loc[20] * x + loc[21] * y + loc[22] * z
                       + loc[23] * xx + loc[24] * yy + loc[25] * zz2
                       + loc[26] * xy + loc[27] * xz + loc[28] * yz)


@jit(fastmath=SIMD_MATH, error_model="numpy", inline="always")
def shift_local(src, dst, tx, ty, tz, potential):
    """dst = src's local expansion moved by t (L2L): F' = F + G t + H[t, t],
    G'_ab = G_ab + 2 H_abk t_k, H' = H; the potential's P0, P1, P2 likewise."""
    gxx, gyy, gzz, gxy, gxz, gyz = src[3], src[4], src[5], src[6], src[7], src[8]
    hxxx, hyyy, hzzz, hxxy, hxxz = src[9], src[10], src[11], src[12], src[13]
    hxyy, hyyz, hxzz, hyzz, hxyz = src[14], src[15], src[16], src[17], src[18]
    xx = tx * tx
    yy = ty * ty
    zz = tz * tz
    xy = 2.0 * tx * ty
    xz = 2.0 * tx * tz
    yz = 2.0 * ty * tz
    dst[0] = (src[0] + gxx * tx + gxy * ty + gxz * tz + hxxx * xx + hxyy * yy + hxzz * zz
              + hxxy * xy + hxxz * xz + hxyz * yz)
    dst[1] = (src[1] + gxy * tx + gyy * ty + gyz * tz + hxxy * xx + hyyy * yy + hyzz * zz
              + hxyy * xy + hxyz * xz + hyyz * yz)
    dst[2] = (src[2] + gxz * tx + gyz * ty + gzz * tz + hxxz * xx + hyyz * yy + hzzz * zz
              + hxyz * xy + hxzz * xz + hyzz * yz)
    dst[3] = gxx + 2.0 * (hxxx * tx + hxxy * ty + hxxz * tz)
    dst[4] = gyy + 2.0 * (hxyy * tx + hyyy * ty + hyyz * tz)
    dst[5] = gzz + 2.0 * (hxzz * tx + hyzz * ty + hzzz * tz)
    dst[6] = gxy + 2.0 * (hxxy * tx + hxyy * ty + hxyz * tz)
    dst[7] = gxz + 2.0 * (hxxz * tx + hxyz * ty + hxzz * tz)
    dst[8] = gyz + 2.0 * (hxyz * tx + hyyz * ty + hyzz * tz)
    for k in range(9, 19):
        dst[k] = src[k]
    if potential:
        p1x, p1y, p1z = src[20], src[21], src[22]
        pxx, pyy, pzz, pxy, pxz, pyz = src[23], src[24], src[25], src[26], src[27], src[28]
        dst[19] = (src[19] + p1x * tx + p1y * ty + p1z * tz + pxx * xx + pyy * yy + pzz * zz
                   + pxy * xy + pxz * xz + pyz * yz)
        dst[20] = p1x + 2.0 * (pxx * tx + pxy * ty + pxz * tz)
        dst[21] = p1y + 2.0 * (pxy * tx + pyy * ty + pyz * tz)
        dst[22] = p1z + 2.0 * (pxz * tx + pyz * ty + pzz * tz)
        for k in range(23, 29):
            dst[k] = src[k]



@jit(error_model="numpy", inline="always")
def flush(ll, count, zx, zy, zz, eps2, loc, potential):
    """loc += the M2L of the ``count`` listed cells (and of their potential, if asked)."""
    cells_to_local(ll, count, zx, zy, zz, eps2, loc)
    if potential:
        cells_to_local_potential(ll, count, zx, zy, zz, eps2, loc)
