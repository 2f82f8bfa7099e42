"""The look of Spacewar! on screen, shared by the Pillow painter and the pygame window:
colours, the ships' outlines and sizes, how long effects last (no drawing code here)."""

VIZ_HINT = "pip install -e '.[viz]'"

# -- looks --------------------------------------------------------------------------------
BLACK = (0, 0, 0)
SHIP_COLOURS = ((120, 205, 255), (255, 180, 80))  # seat 0 (needle), seat 1 (wedge)
TORPEDO_COLOURS = ((205, 240, 255), (255, 232, 150))
FLAME_COLOURS = ((255, 150, 40), (255, 240, 170))  # outer, inner
STAR_CORE = (255, 255, 235)
STAR_RAYS = ((255, 255, 200), (255, 225, 130), (215, 175, 90))
SKY = ((55, 55, 70), (85, 85, 100), (125, 125, 140))
TEXT = (225, 225, 225)
DIM_TEXT = (130, 130, 130)
CHARGE_COLOURS = ((255, 85, 85), (90, 125, 255))  # positive, negative
FIRE = ((255, 255, 255), (255, 245, 185), (255, 215, 100), (255, 160, 50), (235, 100, 35),
        (180, 60, 25), (120, 35, 15), (65, 18, 8))
FADES = (1.0, 0.7, 0.45, 0.25)

SHIP_LENGTH = 0.04  # arena units (about 40 of the PDP-1's 1024 points)
MIN_SHIP_PIXELS = 10.0
#: outlines in units of the ship's length, x forward along the heading, y to the left
NEEDLE = ((0.56, 0.0), (0.32, 0.065), (-0.30, 0.065), (-0.48, 0.17), (-0.48, -0.17),
          (-0.30, -0.065), (0.32, -0.065))
WEDGE = ((0.50, 0.0), (-0.40, 0.27), (-0.50, 0.11), (-0.50, -0.11), (-0.40, -0.27))
SHAPES = (NEEDLE, WEDGE)
EXHAUST = ((-0.48, 0.065), (-0.50, 0.11))  # (x, half width) of each shape's nozzle

EXPLOSION_FRAMES = 48
HYPERSPACE_FLASH_FRAMES = 14
TORPEDO_BURST_FRAMES = 8
FINAL_HOLD_MS = 1500  # the last GIF frame stays up this long

DEFAULT_NAMES = ("needle", "wedge")
TORPEDO_RADIUS_PER_PIXEL = 1.0 / 190.0  # of the image side: 2.5 pixels at 480
MIN_TORPEDO_RADIUS = 2.5  # pixels: a torpedo is a visible dot at any size
