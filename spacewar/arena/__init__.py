"""Bots against bots: one match (``match``), many as rows of one compiled game
(``batch_match``), tournaments and leagues (``tournament``, ``league``, their ratings in
``ratings``), the jobs they are cut into (``jobs``), run on this machine's cores or a Dask
cluster (``runner``, ``cluster``), and the choice of a seat for a bot (``seats``)."""
