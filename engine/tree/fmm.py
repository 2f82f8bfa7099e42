"""The fast multipole walk: cells act on cells, and local expansions are passed down.

``walk`` walks the tree from its root once for every group of targets, so a far region is met
again by every group near it, and the cost grows as N log N. Here the targets are cells too
(Greengard & Rokhlin 1987, J. Comput. Phys. 73, 325; the dual tree walk of Dehnen 2002,
J. Comput. Phys. 179, 27, "falcON"): a target cell T resolves a list of candidate source
cells, and a source S

- that is separated from T (radii summing to less than theta times the distance between
  their centres, and more than 4 ``small`` particle pairs between them) acts once on T's
  local expansion (M2L, ``local``), which T's children inherit, moved to their centres (L2L),
  down to the groups, where it is evaluated at each target (L2P): a far region acts once on
  the largest cell it is far from;
- that is larger than T (by radius) is replaced by its children, which T resolves in turn;
- else waits for T's children: it goes on the list T hands down (with T's own children, for
  the pairs among them).

At a group (a cell of at most ``field.FMM_GROUP_SIZE`` particles, or a leaf) the candidates left
are taken as ``walk.walk_group`` takes them (multipoles at each target, pairs, or opened), so
the near field is the same as the Barnes-Hut walk's, and the far field costs a bounded number
of cells a cell: the number of interactions grows as N.

A source is sent down (and pairs evaluated) from each target's side: every particle's sum is
computed by one thread, with no writes shared between threads, at the price of evaluating
each mutual pair twice (falcON evaluates it once, for both, and so conserves momentum to
round-off; here, as in the Barnes-Hut walk, momentum drifts at the level of the force error).

Threads: the cells of more than ``m / (32 lanes)`` particles (and not groups) are resolved by
every lane alike; their other children, in depth-first order, are dealt round-robin to the
lanes, each of which then walks its own subtrees depth first with its own frames. Every
target's sums are the same operations in the same order whichever lane makes them: the same
bits at any thread count.

The scratch is fixed (``layout.lane_descent``): per level of the path a frame with its local
expansion, and the candidate lists of the path's cells. A scene that needs more (a tree deeper
than ``layout.DEPTH`` levels, or lists longer than ``layout.CANDIDATES``: theta well below
0.3 at 10^6 particles) reports it, and ``field.solve`` walks it by ``walk`` instead.
"""
from numba import prange

from ..cache import jit

from . import layout, local, multipoles as mp, walk as wk

#: a cell of more than m / (SHARE_LANES lanes) particles is resolved by every lane; its other
#: children are dealt to the lanes (about SHARE_LANES subtrees a lane: enough to even them out)
SHARE_LANES = 32


@jit(error_model="numpy", inline="always")
def is_group(c, count, children, group_size):
    return children[c] == 0 or count[c] <= group_size


@jit(error_model="numpy")
def resolve(T, ws, we, loc, cand, deferred, px, py, pz, beta, ax, ay, az, phi, cells, start,
            count, child, children, lx, ly, lz, lb, lc, ll, theta2, eps2, order,
            potential, small, group_size):
    """Resolve target cell T against the candidates cand[ws:we) (module doc), its expansion
    ``loc`` holding what its ancestors handed down. A group's targets get their sums; another
    cell's list for its children is left at cand[ws:ws + k], and k returned; -1 if the
    candidates outgrow ``cand``.

    At a group the candidates are taken as ``walk.walk_group`` takes them, in the same code
    written out here: a shared function for it (inlined by numba, or not) made this walk 20%
    slower and its one-thread run 35% (measured at 10^6 bodies), so the two loops are kept
    alike by hand: a change to one is a change to the other."""
    isgroup = is_group(T, count, children, group_size)
    zx = cells[mp.CX, T]
    zy = cells[mp.CY, T]
    zz = cells[mp.CZ, T]
    reach = cells[mp.RADIUS, T]
    glx = cells[mp.LOX, T]
    gly = cells[mp.LOY, T]
    glz = cells[mp.LOZ, T]
    ghx = cells[mp.HIX, T]
    ghy = cells[mp.HIY, T]
    ghz = cells[mp.HIZ, T]
    s = start[T]
    e = s + count[T]
    if isgroup:
        for i in range(s, e):
            ax[i] = 0.0
            ay[i] = 0.0
            az[i] = 0.0
            if potential:
                phi[i] = 0.0
    plist = lx.shape[0]
    clist = lc.shape[1]
    cap = cand.shape[0]
    npart = 0
    ncell = 0
    nlocal = 0
    ndef = 0
    i = ws
    end = we
    while i < end:
        S = cand[i]
        i += 1
        if cells[mp.ABSW, S] == 0.0:
            continue
        if S == T:
            if isgroup:
                wk.sum_own_group(px, py, pz, beta, s, e, eps2, ax, ay, az, phi, potential)
            else:  # the pairs among its children: theirs to resolve
                if ndef + children[T] > deferred.shape[0]:
                    return -1
                for k in range(child[T], child[T] + children[T]):
                    deferred[ndef] = k
                    ndef += 1
            continue
        rx = cells[mp.CX, S] - zx
        ry = cells[mp.CY, S] - zy
        rz = cells[mp.CZ, S] - zz
        radius = cells[mp.RADIUS, S]
        spread = radius + reach
        # separated: acts on T's expansion (the condition of ``walk.walk_group``)
        if count[S] * count[T] > 4 * small and spread * spread < theta2 * (rx * rx + ry * ry
                                                                            + rz * rz):
            if nlocal == clist:
                local.flush(ll, nlocal, zx, zy, zz, eps2, loc, potential)
                nlocal = 0
            wk.copy_cell(cells, S, ll, nlocal, order)
            nlocal += 1
            continue
        if isgroup:
            dx = wk.gap(glx, ghx, cells[mp.CX, S])
            dy = wk.gap(gly, ghy, cells[mp.CY, S])
            dz = wk.gap(glz, ghz, cells[mp.CZ, S])
            d2 = dx * dx + dy * dy + dz * dz
            size = cells[mp.SIZE, S]
            far = size * size < theta2 * d2 and d2 > radius * radius
            if far and count[S] > small:
                if ncell == clist:
                    wk.sum_cells(px, py, pz, s, e, lc, ncell, eps2, ax, ay, az, phi, potential)
                    ncell = 0
                wk.copy_cell(cells, S, lc, ncell, order)
                ncell += 1
            elif far or children[S] == 0:
                for k in range(start[S], start[S] + count[S]):
                    if beta[k] == 0.0:
                        continue
                    if npart == plist:
                        wk.sum_particles(px, py, pz, s, e, lx, ly, lz, lb, npart, eps2, ax, ay,
                                         az, phi, potential)
                        npart = 0
                    lx[npart] = px[k]
                    ly[npart] = py[k]
                    lz[npart] = pz[k]
                    lb[npart] = beta[k]
                    npart += 1
            else:
                if end + children[S] > cap:
                    return -1
                for k in range(child[S], child[S] + children[S]):
                    cand[end] = k
                    end += 1
        elif children[S] > 0 and radius > reach:  # larger than T: opened
            if end + children[S] > cap:
                return -1
            for k in range(child[S], child[S] + children[S]):
                cand[end] = k
                end += 1
        else:  # waits for T's children
            if ndef == deferred.shape[0]:
                return -1
            deferred[ndef] = S
            ndef += 1
    if nlocal:
        local.flush(ll, nlocal, zx, zy, zz, eps2, loc, potential)
    if isgroup:
        if npart:
            wk.sum_particles(px, py, pz, s, e, lx, ly, lz, lb, npart, eps2, ax, ay, az, phi,
                             potential)
        if ncell:
            wk.sum_cells(px, py, pz, s, e, lc, ncell, eps2, ax, ay, az, phi, potential)
        local.local_to_targets(px, py, pz, s, e, zx, zy, zz, loc, ax, ay, az, phi, potential)
        return 0
    if ws + ndef > cap:
        return -1
    for k in range(ndef):
        cand[ws + k] = deferred[k]
    return ndef


@jit(error_model="numpy")
def descend_lane(lane, lanes, floats, ints, n, m, theta2, eps2, order, potential,
                 small, group_size):
    """Lane ``lane``'s share of the walk (module doc): 0, or -1 if its scratch ran out."""
    part = layout.particle_blocks(floats, n)
    cells = layout.cell_table(floats, n)
    start, count, child, children, groups = layout.cell_links(ints, n)
    lx, ly, lz, lb, lc, ll, loc = layout.lane_lists(floats, n, lane)
    cand, deferred, fcell, fnext, fstart, flen, floc = layout.lane_descent(floats, ints, n,
                                                                          lane)
    px, py, pz, beta = part[0], part[1], part[2], part[3]
    ax, ay, az, phi = part[5], part[6], part[7], part[8]
    share = max(m // (lanes * SHARE_LANES), group_size)
    shared_root = count[0] > share and not is_group(0, count, children, group_size)
    if lane != 0 and not shared_root:
        return 0
    for k in range(floc.shape[1]):
        floc[0, k] = 0.0
    cand[0] = 0  # the root's one candidate: itself
    ndef = resolve(0, 0, 1, floc[0], cand, deferred, px, py, pz, beta, ax, ay, az, phi, cells,
                   start, count, child, children, lx, ly, lz, lb, lc, ll, theta2,
                   eps2, order, potential, small, group_size)
    if ndef < 0:
        return -1
    depth = 0
    fcell[0] = 0
    fnext[0] = child[0]
    fstart[0] = 0
    flen[0] = ndef
    dealt = 0
    while depth >= 0:
        t = fcell[depth]
        k = fnext[depth]
        if is_group(t, count, children, group_size) or k == child[t] + children[t]:
            depth -= 1
            continue
        fnext[depth] = k + 1
        if count[t] > share and (count[k] <= share or is_group(k, count, children,
                                                                group_size)):
            dealt += 1  # a subtree dealt to one lane
            if (dealt - 1) % lanes != lane:
                continue
        if depth + 1 == fcell.shape[0]:
            return -1
        # k's candidates: a copy of its parent's list, on top of it
        ws = fstart[depth] + flen[depth]
        size = flen[depth]
        if ws + size > cand.shape[0]:
            return -1
        for j in range(size):
            cand[ws + j] = cand[fstart[depth] + j]
        local.shift_local(floc[depth], floc[depth + 1], cells[mp.CX, k] - cells[mp.CX, t],
                          cells[mp.CY, k] - cells[mp.CY, t], cells[mp.CZ, k] - cells[mp.CZ, t],
                          potential)
        ndef = resolve(k, ws, ws + size, floc[depth + 1], cand, deferred, px, py, pz, beta, ax,
                       ay, az, phi, cells, start, count, child, children, lx, ly, lz, lb, lc,
                       ll, theta2, eps2, order, potential, small, group_size)
        if ndef < 0:
            return -1
        depth += 1
        fcell[depth] = k
        fnext[depth] = child[k]
        fstart[depth] = ws
        flen[depth] = ndef
    return 0


#: one signature for both (see ``walk.SIGNATURE``)
SIGNATURE = ("void(float64[::1], int64[::1], int64, int64, float64, float64, int64, boolean, "
             "int64, int64, int64)")


@jit(signature=SIGNATURE, parallel=True, error_model="numpy")
def descend(floats, ints, n, m, theta2, eps2, order, potential, small, group_size,
            lanes):
    """The walk on ``lanes`` lanes (module doc), each lane's outcome in its
    ``layout.lane_status``: 0, or -1 if its scratch ran out (its sums are then incomplete:
    walk again by ``walk``)."""
    for lane in prange(lanes):
        layout.lane_status(ints, n, lane)[0] = descend_lane(
            lane, lanes, floats, ints, n, m, theta2, eps2, order, potential, small,
            group_size)


@jit(signature=SIGNATURE, error_model="numpy")
def descend_serial(floats, ints, n, m, theta2, eps2, order, potential, small,
                   group_size, lanes):
    """``descend`` on the calling thread, as lane 0 of 1."""
    layout.lane_status(ints, n, 0)[0] = descend_lane(0, 1, floats, ints, n, m, theta2,
                                                     eps2, order, potential, small,
                                                     group_size)


@jit(error_model="numpy", inline="always")
def succeeded(ints, n, lanes):
    """Did every one of ``lanes`` lanes finish?"""
    for lane in range(lanes):
        if layout.lane_status(ints, n, lane)[0] != 0:
            return False
    return True

