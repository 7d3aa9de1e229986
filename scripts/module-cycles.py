#!/usr/bin/env python3
"""Import cycles and layer violations between the modules of the library.

Graphs checked: the crate's top modules (design, model, integrate, decide,
...; the study's three rooms, study::plan, study::results and study::run,
count as modules of their own), the units inside `model`, the rooms of
`study`, and the units inside `decide` and inside each room. A "unit"
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
    # The study's rooms and the decision between them: the study file, what
    # runs leave, the decision over them, the runner that uses all three, and
    # the verbs on top of the runner (the rest of `study`).
    {"study::plan"},
    {"study::results"},
    {"decide"},
    {"study::run"},
    {"study"},
    {"optimize", "claims", "tradeoff", "check", "plot", "schema", "report", "calibrate", "text"},
]
MODEL_LAYERS = [
    {"validate", "cargo", "speed", "rotor", "effect", "balancer", "trig", "race_ring", "coupling",
     "tilt_inertia", "sommerfeld", "rigid_contact"},
    {"system", "frame", "scene", "forced", "gap", "invariants", "linear", "balanced_family", "quasi_static", "start",
     "unbalance", "zero_approx", "critical_speeds"},
]
# Inside each room, lowest first.
PLAN_LAYERS = [
    {"stream", "truncated", "distribution", "design", "optimize_spec", "criterion", "tie_break"},
    {"couple", "tolerance", "plane_designs"},
    {"config"},
    {"sample"},
]
RESULTS_LAYERS = [
    {"io", "measured_runs", "summary_columns", "causes_file"},
    {"results_table", "record"},
    {"runs_file"},
    {"design_runs"},
]
DECIDE_LAYERS = [
    {"measure", "diagnosis", "failures", "causes"},
    {"verdict", "plane_summary"},
    # Robustness tests #1 within each third by the verdicts' rule.
    {"decision", "compare_designs", "robustness"},
]
RUN_LAYERS = [
    {"lock", "racing"},
    {"adaptive", "aggregate"},
    # The executor (run/mod.rs and its private files) and what uses it.
    {"mod", "assemble", "executor", "folder", "causes"},
    {"merge", "study_folder"},
]
STUDY_LAYERS = [
    {"plan"},
    {"results"},
    {"run"},
    {"sweep", "stability_map", "sensitivity", "stepped_bands"},
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


ROOMS = {"plan", "results", "run"}


def crate_unit(path: tuple) -> tuple:
    """A module path with the study's rooms joined into one crate-level unit."""
    if len(path) >= 2 and path[0] == "study" and path[1] in ROOMS:
        return ("study::" + path[1],) + path[2:]
    return path


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


def analyse(files, modules, depth: int, title: str, layers, unit=lambda p: p) -> int:
    """Edges between the units at `depth` (0: crate modules, 1: inside one,
    2: inside a room), after `unit` renames a path."""
    edges = {}
    for f in files:
        here = unit(module_path(f))
        code = CODE_NOISE.sub(" ", f.read_text())
        paths = [p for tree in USE.findall(code) for p in expand(tree)]
        code_wo_use = USE.sub(" ", code)
        paths += [re.sub(r"\s+", "", m) for m in INLINE.findall(code_wo_use)]
        for p in paths:
            target = resolve(p, module_path(f), modules)
            target = unit(target) if target else None
            if not target or len(target) <= depth or len(here) <= depth:
                continue
            if target[:depth] != here[:depth]:
                continue
            a, b = here[depth], target[depth]
            if a != b:
                edges.setdefault(a, {}).setdefault(b, set()).add(
                    "/".join(f.relative_to(ROOT).parts)
                )
    units = sorted({unit(module_path(f))[depth] for f in files if len(unit(module_path(f))) > depth})

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


def in_room(path: tuple) -> tuple:
    """A path inside a room, with the room's own module (mod.rs) as unit "mod"."""
    return path + ("mod",) if len(path) == 2 else path


def main() -> int:
    files = sorted(p for p in ROOT.rglob("*.rs") if "bin" not in p.relative_to(ROOT).parts)
    modules = {module_path(f) for f in files}
    bad = analyse(files, modules, 0, "crate module", CRATE_LAYERS, crate_unit)
    model_files = [f for f in files if module_path(f)[:1] == ("model",)]
    bad += analyse(model_files, modules, 1, "model unit", MODEL_LAYERS)
    study_files = [f for f in files if module_path(f)[:1] == ("study",)]
    bad += analyse(study_files, modules, 1, "study room", STUDY_LAYERS)
    decide_files = [f for f in files if module_path(f)[:1] == ("decide",)]
    bad += analyse(decide_files, modules, 1, "decide unit", DECIDE_LAYERS)
    for room, layers in (("plan", PLAN_LAYERS), ("results", RESULTS_LAYERS), ("run", RUN_LAYERS)):
        room_files = [f for f in files if module_path(f)[:2] == ("study", room)]
        unit = in_room if room == "run" else (lambda p: p)
        bad += analyse(room_files, modules, 2, f"study::{room} unit", layers, unit)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
