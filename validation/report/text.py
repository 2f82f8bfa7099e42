"""The report's number formatting and Markdown tables, shared by its sections."""
import math


def f(x, digits=2):
    """A number in scientific notation for tables; a dash for missing values."""
    if x is None:
        return "—"
    if isinstance(x, str):
        return x
    if not math.isfinite(x):
        return "inf" if x > 0 else "nan"
    if x == 0:
        return "0"
    return f"{x:.{digits - 1}e}"


def g(x, digits=3):
    return "—" if x is None else f"{x:.{digits}g}"


def expo(x):
    """A growth exponent: two decimals (no '-0.00')."""
    if x is None:
        return "—"
    return f"{0.0 if abs(x) < 0.005 else x:.2f}"


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(str(c).replace("|", "\\|") for c in row) + " |" for row in rows]
    return "\n".join(out)


def seconds(s):
    return f"{s:.3g} s" if s < 100 else f"{s / 60:.1f} min"


def label_of(method):
    """``engine:leapfrog`` -> ``leapfrog``; ``rebound:ias15`` -> ``REBOUND ias15``."""
    code, name = method.split(":")
    return name if code == "engine" else f"REBOUND {name}"
