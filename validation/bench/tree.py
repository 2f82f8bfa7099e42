"""Section 11: the tree's gravity, by its fast multipole walk and its Barnes-Hut walk, on a
Plummer sphere against pytreegrav's and REBOUND's trees at equal median force error, its scaling
with N, its crossover with the direct sum and its memory (the measurements:
``validation.tree_bench``)."""
import sys

from .. import tree_bench

NAME = "tree"
KEYS = ("tree",)
NEEDS = ()  # the codes that are not installed are skipped, and said so


def run(quick):
    return {"tree": tree_bench.measure(tree_bench.SIZES["quick" if quick else "full"],
                                       progress=lambda text: print(text, file=sys.stderr))}


def text(r):
    return (["\n11. Tree gravity (FMM and Barnes-Hut) against pytreegrav and REBOUND at equal "
             "error"] + tree_bench.format_tree(r["tree"]))


def markdown(r):
    return (["## 11. Tree gravity (`NBodyGravity(method=\"fmm\")` and `method=\"tree\"`)", ""]
            + tree_bench.markdown_tree(r["tree"]) + [""])


def targets(r):
    return tree_bench.targets(r["tree"])
