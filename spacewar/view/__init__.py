"""Watching: how things look (``look``), a frame as drawing primitives (``scene``), painted by
Pillow (``paint_pil``, ``gif``) or pygame (``window``, ``replay_view``), keys (``keys``) and
playing or watching live (``live``). Pillow and pygame are the ``[viz]`` extra, imported only
when something is drawn."""
