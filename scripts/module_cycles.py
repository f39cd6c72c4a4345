#!/usr/bin/env python3
"""Cycles among the top-level modules of crates/cloudscape/src.

Reads every non-test Rust file, records which top-level modules each top-level module names
(`crate::x`, `super::x` from a top-level file's child, `use crate::{x, y}`), and prints the
strongly connected components with more than one module, with one reference per edge as evidence.
Exit status 1 when there is a cycle. Usage: python3 scripts/module_cycles.py
"""
import pathlib, re, sys

SRC = pathlib.Path(__file__).resolve().parent.parent / "crates/cloudscape/src"


def top_module(path):
    rel = path.relative_to(SRC).parts
    return rel[0].removesuffix(".rs") if rel[0] != "lib.rs" else None


def strip_tests(text):
    # Drop `#[cfg(test)] mod tests { ... }` blocks (and any cfg(test) item up to its braces' end).
    out, i = [], 0
    while True:
        j = text.find("#[cfg(test)]", i)
        if j < 0:
            out.append(text[i:])
            return "".join(out)
        out.append(text[i:j])
        k = text.find("{", j)
        semi = text.find(";", j)
        if semi >= 0 and (k < 0 or semi < k):
            i = semi + 1
            continue
        depth, p = 0, k
        while p < len(text):
            depth += {"{": 1, "}": -1}.get(text[p], 0)
            p += 1
            if depth == 0:
                break
        i = p


def references(text, modules):
    text = re.sub(r"//[^\n]*", "", text)
    found = {}
    for m in re.finditer(r"crate::\{([^}]*)\}", text):
        for name in re.findall(r"\b([a-z_][a-z0-9_]*)\b", m.group(1)):
            found.setdefault(name, m.group(0)[:60])
    for m in re.finditer(r"crate::([a-z_][a-z0-9_]*)", text):
        found.setdefault(m.group(1), m.group(0))
    return {k: v for k, v in found.items() if k in modules}


def main():
    files = [p for p in SRC.rglob("*.rs") if p.name not in ("tests.rs",) and not p.name.endswith("_tests.rs")]
    modules = {top_module(p) for p in files} - {None}
    edges = {m: {} for m in modules}
    for p in files:
        src = top_module(p)
        if src is None:
            continue
        for dst, evidence in references(strip_tests(p.read_text()), modules).items():
            if dst != src:
                edges[src].setdefault(dst, f"{p.relative_to(SRC)}: {evidence}")
    index, low, stack, on, sccs, counter = {}, {}, [], set(), [], [0]

    def connect(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                connect(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            scc = []
            while True:
                w = stack.pop()
                on.discard(w)
                scc.append(w)
                if w == v:
                    break
            sccs.append(scc)

    sys.setrecursionlimit(10000)
    for v in sorted(modules):
        if v not in index:
            connect(v)
    cycles = [sorted(s) for s in sccs if len(s) > 1]
    for scc in cycles:
        print("cycle:", " ".join(scc))
        for a in scc:
            for b in scc:
                if b in edges[a]:
                    print(f"  {a} -> {b}   ({edges[a][b]})")
    if not cycles:
        print(f"{len(modules)} top-level modules, no cycles")
    sys.exit(1 if cycles else 0)


main()
