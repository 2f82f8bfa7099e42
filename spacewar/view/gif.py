"""A replay drawn as an animated GIF (``render_gif``): re-simulated frame by frame
(``spacewar.replay``), each frame painted with Pillow (``spacewar.view.paint_pil``) and written as it
comes, atomically."""
import os

import numpy as np

from engine.atomic import atomic_write, check_output_path

from spacewar.view.look import DEFAULT_NAMES, FINAL_HOLD_MS
from spacewar.view.paint_pil import (PALETTE_BYTES, TRANSPARENT, check_size, render_frame,
                                     require_pillow)
from spacewar.view.scene import Effects, frame_snapshot


# -- GIF output ---------------------------------------------------------------------------
class _GifWriter:
    """Writes frames as they come: each frame after the first holds only the box that changed,
    with unchanged pixels transparent, so memory stays flat however long the match.

    Uses Pillow's GIF header and frame encoders (``GifImagePlugin.getheader`` / ``getdata``);
    if a Pillow lacks them, frames are kept and saved by ``Image.save(save_all=True)``.
    A frame identical to the one before only lengthens that one's display time.
    """

    def __init__(self, stream, fps):
        from PIL import GifImagePlugin

        self._gif = GifImagePlugin
        self.streaming = hasattr(GifImagePlugin, "getheader") and hasattr(GifImagePlugin, "getdata")
        self.stream = stream
        self.fps = fps
        self.added = 0  # frames given to add()
        self.written = 0  # GIF frames in the file
        self._pending = None  # [pixels, image, centiseconds]: held back to merge or extend
        self._last = None  # pixels of the last frame written
        self._kept = []  # (image, centiseconds) when not streaming

    def add(self, image):
        # whole centiseconds whose running total tracks the exact frame times (30 fps: 3,3,4,..)
        cs = round(100 * (self.added + 1) / self.fps) - round(100 * self.added / self.fps)
        self.added += 1
        pixels = np.asarray(image)
        if self._pending is not None and np.array_equal(pixels, self._pending[0]):
            self._pending[2] += cs
            return
        if self._pending is not None:
            self._write(*self._pending)
        self._pending = [pixels, image, cs]

    def close(self, hold_ms=FINAL_HOLD_MS):
        if self._pending is not None:
            self._pending[2] += hold_ms // 10
            self._write(*self._pending)
            self._pending = None
        if self.streaming:
            if self.written:
                self.stream.write(b";")
        elif self._kept:
            images = [im for im, _ in self._kept]
            images[0].save(self.stream, format="GIF", save_all=True, append_images=images[1:],
                           duration=[10 * cs for _, cs in self._kept], loop=0, optimize=True)
            self.written = len(images)

    def _write(self, pixels, image, cs):
        cs = max(1, min(cs, 65535))
        if not self.streaming:
            self._kept.append((image, cs))
            return
        if self._last is None:
            header, _ = self._gif.getheader(image, None, {"loop": 0, "duration": 10 * cs})
            chunks = list(header) + list(self._gif.getdata(image, (0, 0), duration=10 * cs,
                                                           disposal=1))
        else:
            changed = pixels != self._last
            rows = np.flatnonzero(changed.any(axis=1))
            cols = np.flatnonzero(changed.any(axis=0))
            y0, y1, x0, x1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
            box = np.where(changed[y0:y1, x0:x1], pixels[y0:y1, x0:x1], TRANSPARENT).astype(np.uint8)
            Image, _, _ = require_pillow()
            delta = Image.frombytes("P", (int(x1 - x0), int(y1 - y0)), box.tobytes())
            delta.putpalette(PALETTE_BYTES)
            chunks = self._gif.getdata(delta, (int(x0), int(y0)), duration=10 * cs, disposal=1,
                                       transparency=TRANSPARENT)
        for chunk in chunks:
            self.stream.write(chunk)
        self._last = pixels
        self.written += 1


class _Enough(Exception):
    """Raised inside the replay callback once ``max_frames`` frames are drawn."""


def render_gif(replay, out_path, every=2, size=480, fps=30, max_frames=None):
    """Draw a replay as an animated GIF at ``out_path``; return a summary dict.

    ``replay``: a replay dict or the path of a replay file. Every ``every``-th game frame is
    drawn (and the last one); the GIF plays ``fps`` of those a second (30 with ``every=2``
    shows the game at 60 frames a second, about the original's pace) and holds the final
    frame a moment. ``max_frames`` stops after that many drawn frames. ``out_path`` is checked
    first (``engine.atomic.check_output_path(out_path, "gif")``: a missing directory, or an
    existing file that is not a GIF, such as the replay itself, is refused before anything is
    drawn); the file is written by ``engine.atomic.atomic_write`` (a temporary file beside it,
    moved into place at the end), so a crash or an interrupt never leaves a partial GIF there.
    """
    if isinstance(every, bool) or not isinstance(every, int) or every < 1:
        raise ValueError(f"every must be an int >= 1, got {every!r}")
    size = check_size(size)
    if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not 0 < fps <= 50:
        raise ValueError(f"fps must be a number in (0, 50] (GIF frame times are whole "
                         f"hundredths of a second and viewers slow faster ones), got {fps!r}")
    if max_frames is not None and (isinstance(max_frames, bool) or not isinstance(max_frames, int)
                                   or max_frames < 1):
        raise ValueError(f"max_frames must be None or an int >= 1, got {max_frames!r}")
    require_pillow()
    out_path = check_output_path(out_path, "gif")  # before any work: never over a replay
    from spacewar.replay import load, simulate

    if isinstance(replay, (str, bytes, os.PathLike)):
        replay = load(replay)
    names = tuple(replay.get("bots") or DEFAULT_NAMES)
    rounds = replay.get("rounds")
    effects = Effects()
    last = {"frame": 0}
    state = {}

    def draw(f):
        writer = state["writer"] = _GifWriter(f, fps)

        def on_frame(game):
            snap = game.snapshot(0)
            effects.update(snap)
            last["frame"] = snap["frame"]
            if snap["frame"] % every == 0 or snap["over"]:
                writer.add(render_frame(frame_snapshot(game), size, effects=effects, names=names,
                                        rounds=rounds))
                if max_frames is not None and writer.added >= max_frames:
                    raise _Enough

        try:
            simulate(replay, on_frame)
        except _Enough:
            pass
        writer.close()

    atomic_write(out_path, draw, "wb")  # never a partial GIF at out_path; mode 0o666 & ~umask
    writer = state["writer"]
    return {"path": out_path, "frames": writer.written, "drawn": writer.added,
            "game_frames": last["frame"], "size": size, "bytes": os.path.getsize(out_path)}
