#!/usr/bin/env python3
"""Import cycles and layer violations between the modules of the library.

Three graphs are checked: the crate's top modules (design, model, integrate,
study, ...), the units inside `model` and the units inside `study`. A "unit"
is a direct child of its parent (a file such as scene.rs, or a folder such as rotor/ together with
everything below it): edges inside a unit (a file using its folder's mod.rs
and the re-exports back) are how Rust folders work and are not counted.
Every `use` tree and every inline `crate::…`/`super::…` path outside
comments and strings is an edge.

Exits 1 when any graph has a cycle or a module imports one from a higher
layer, so it can run in CI: python3 scripts/module-cycles.py
"""

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent / "src"

# Layers, lowest first: a module may import its own layer and the ones below.
CRATE_LAYERS = [
    {"stats", "design", "integrate", "build_info", "input_file", "invalid_key", "output_file", "number_text", "pair"},
    {"model"},
    {"metrics"},
    {"simulation", "scene_file", "uncertain"},
    {"study"},
    {"optimize", "claims", "tradeoff", "check", "plot", "schema", "report", "calibrate"},
]
MODEL_LAYERS = [
    {"validate", "cargo", "speed", "rotor", "effect", "balancer", "trig", "race_ring", "coupling",
     "tilt_inertia", "sommerfeld", "rigid_contact"},
    {"system", "frame", "scene", "forced", "gap", "invariants", "linear", "balanced_family", "quasi_static", "start",
     "unbalance", "zero_approx", "critical_speeds"},
]
STUDY_LAYERS = [
    # Plain data and helpers: streams, distributions, a resolved design, a
    # design's measured runs, files.
    {"stream", "truncated", "distribution", "design", "measured_runs", "io", "lock", "runs_file", "summary_columns", "results_table"},
    # The parts of the study file that check, draw or measure on their own.
    {"couple", "tolerance", "plane_designs", "criterion", "optimize_spec"},
    # The study file and its resolved plan.
    {"config"},
    # One run or one design, from a plan.
    {"sample", "record", "failures", "diagnosis", "design_runs", "verdict", "plane_summary"},
    # Statistics over many runs.
    {"adaptive", "aggregate", "compare_designs", "decision", "racing", "robustness"},
    # The runner and the verbs on top of it.
    {"run", "merge", "study_folder", "sweep", "stability_map", "sensitivity", "stepped_bands"},
]

CODE_NOISE = re.compile(
    r'//[^\n]*|/\*.*?\*/|r#*"(?:.|\n)*?"#*|"(?:\\.|[^"\\])*"|\'(?:\\.|[^\'\\])\'',
    re.S,
)
USE = re.compile(r"\buse\s+([^;]+);")
INLINE = re.compile(r"\b(?:crate|super|self)(?:\s*::\s*\w+)+")


def module_path(file: Path) -> tuple:
    rel = file.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "mod":
        parts.pop()
    return tuple(parts)


def expand(tree: str) -> list:
    """All leaf paths of a use tree such as `super::{a::{self, B}, c}`."""
    tree = re.sub(r"\s+", "", tree)
    depth, start = 0, None
    for i, ch in enumerate(tree):
        if ch == "{":
            if depth == 0:
                start = i
            depth += 1
        elif ch == "}":
            depth -= 1
            if depth == 0:
                prefix, inner, rest = tree[:start], tree[start + 1 : i], tree[i + 1 :]
                out, depth2, last = [], 0, 0
                for j, c in enumerate(inner + ","):
                    if c in "{":
                        depth2 += 1
                    elif c in "}":
                        depth2 -= 1
                    elif c == "," and depth2 == 0:
                        piece = inner[last:j]
                        last = j + 1
                        if piece:
                            out += expand(prefix + piece + rest)
                return out
    return [tree.split(" as ")[0]]


def resolve(path: str, here: tuple, modules: set):
    parts = [p for p in path.split("::") if p]
    # The module a relative path starts from: a file's own module for self,
    # its parent for super (mod.rs files are their folder's module).
    base = list(here)
    if parts[0] == "crate":
        base, parts = [], parts[1:]
    elif parts[0] in ("super", "self"):
        while parts and parts[0] in ("super", "self"):
            if parts[0] == "super":
                base = base[:-1]
            parts = parts[1:]
    else:
        return None
    full = tuple(base + parts)
    for n in range(len(full), 0, -1):
        if full[:n] in modules:
            return full[:n]
    return None


def analyse(files, modules, depth: int, title: str, layers) -> int:
    """Edges between the units at `depth` (0: crate modules, 1: inside one)."""
    edges = {}
    for f in files:
        here = module_path(f)
        code = CODE_NOISE.sub(" ", f.read_text())
        paths = [p for tree in USE.findall(code) for p in expand(tree)]
        code_wo_use = USE.sub(" ", code)
        paths += [re.sub(r"\s+", "", m) for m in INLINE.findall(code_wo_use)]
        for p in paths:
            target = resolve(p, here, modules)
            if not target or len(target) <= depth or len(here) <= depth:
                continue
            if target[:depth] != here[:depth]:
                continue
            a, b = here[depth], target[depth]
            if a != b:
                edges.setdefault(a, {}).setdefault(b, set()).add(
                    "/".join(f.relative_to(ROOT).parts)
                )
    units = sorted({module_path(f)[depth] for f in files if len(module_path(f)) > depth})

    print(f"{title} -> units it imports")
    for u in units:
        print(f"  {u:13} -> {', '.join(sorted(edges.get(u, {}))) or '-'}")

    # Tarjan's strongly connected components.
    index, low, stack, on, sccs, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges.get(v, {}):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                sccs.append(sorted(comp))

    for u in units:
        if u not in index:
            visit(u)

    level = {u: i for i, layer in enumerate(layers) for u in layer}
    bad = 0
    for u in units:
        if u not in level and u not in ("lib", "main"):
            bad += 1
            print(f"UNPLACED: {u} is in no layer (add it to the script's layer list)")
    for comp in sccs:
        bad += 1
        print(f"CYCLE among: {', '.join(comp)}")
        for a in comp:
            for b in comp:
                if b in edges.get(a, {}):
                    print(f"  {a} -> {b}  ({', '.join(sorted(edges[a][b]))})")
    for a in sorted(edges):
        for b in sorted(edges[a]):
            if a in level and b in level and level[b] > level[a]:
                bad += 1
                print(f"LAYER: {a} imports higher {b}  ({', '.join(sorted(edges[a][b]))})")
    print("no cycles, layers respected" if not bad else f"{bad} problem(s)")
    return bad


def main() -> int:
    files = sorted(p for p in ROOT.rglob("*.rs") if "bin" not in p.relative_to(ROOT).parts)
    modules = {module_path(f) for f in files}
    bad = analyse(files, modules, 0, "crate module", CRATE_LAYERS)
    model_files = [f for f in files if module_path(f)[:1] == ("model",)]
    bad += analyse(model_files, modules, 1, "model unit", MODEL_LAYERS)
    study_files = [f for f in files if module_path(f)[:1] == ("study",)]
    bad += analyse(study_files, modules, 1, "study unit", STUDY_LAYERS)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
