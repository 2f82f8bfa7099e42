"""A Barnes-Hut tree for pair forces of the form a_i = alpha_i sum_j beta_j d_ij / r_ij^3.

Gravity (alpha = 1, beta_j = G m_j) and Coulomb's law (alpha_i = -k q_i / m_i, beta_j = q_j)
share it (``engine.forces.gravity_tree``, ``engine.forces.coulomb_tree``). Every evaluation,
in compiled code and without allocating:

1. ``morton``: the particles' Morton keys (a Z-order space-filling curve: Morton 1966) in the
   cube that bounds them, sorted by a radix sort, so that every cell of the tree is a
   contiguous range of the sorted particles;
2. ``build``: the cells, found by splitting sorted ranges where their keys first differ (a
   compressed octree, quadtree in 2-D: a cell is split only where its particles really part,
   so no cell has a single child), then their bounding boxes and multipoles computed bottom-up
   (leaves from their particles, every other cell from its children: ``multipoles``);
3. ``walk``: for each group of at most 64 neighbouring particles, one walk of the tree makes
   the lists of what acts on them (cells far enough to take by their multipoles, the farthest
   of those summed into one local expansion about the group's centre, particles near enough
   to sum directly); the lists are then summed in branch-free loops the compiler vectorises.
   The groups are spread over the cores; each group's lists and sums depend on nothing else,
   so the result is the same bits at any thread count.

Scratch lives in an ``engine.state.Workspace`` sized by ``layout.workspace(n)`` once per
particle count (``layout`` says what each block holds and what it costs per particle).
"""
