#!/usr/bin/env python3
"""Layout figures of the workspace: lines per crate, the longest non-test
functions, and import circles between the files of a crate.

Why a script: no maintained tool reports "functions over N lines" and
"module-file cycles" for Rust (clippy's too_many_lines counts differently and
per function only; cargo-modules draws graphs but does not list cycles of
files), and these are the figures the project keeps down.

    python3 .ci/layout.py            # report
    python3 .ci/layout.py --check    # exit 1 on a function over 120 lines or a circle

A function counts from its `fn` line to its closing brace. Test code does not
count: files under `tests/` or `benches/`, files named `tests.rs`/`fuzz.rs`/
`testbench.rs`, and `#[cfg(test)]` modules. A circle is a cycle of `crate::`/
`super::` references between the files of one crate (references to the crate
root or a `mod.rs` that only declares children are not edges).
"""
import os
import re
import subprocess
import sys

MAX_FN = 120
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def tracked_rs():
    out = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "*.rs"],
                         cwd=ROOT, capture_output=True, text=True, check=True).stdout
    return [p for p in out.split("\n") if p and os.path.exists(os.path.join(ROOT, p))]


def strip(src):
    """Source with comments, strings and char literals blanked (newlines kept)."""
    out = []
    i, n = 0, len(src)
    while i < n:
        c = src[i]
        if src.startswith("//", i):
            j = src.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif src.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if src.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif src.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(re.sub(r"[^\n]", " ", src[i:j]))
            i = j
        elif c == "r" and re.match(r'r#*"', src[i:i + 10]) and (i == 0 or not (src[i - 1].isalnum() or src[i - 1] == "_")):
            m = re.match(r'r(#*)"', src[i:])
            hashes = m.group(1)
            end = src.find('"' + hashes, i + len(m.group(0)))
            end = n if end < 0 else end + 1 + len(hashes)
            out.append(re.sub(r"[^\n]", " ", src[i:end]))
            i = end
        elif c == '"':
            j = i + 1
            while j < n and src[j] != '"':
                j += 2 if src[j] == "\\" else 1
            out.append(re.sub(r"[^\n]", " ", src[i:j + 1]))
            i = j + 1
        elif c == "'":
            m = re.match(r"'(\\.[^']*|[^'\\])'", src[i:])
            if m:
                out.append(" " * len(m.group(0)))
                i += len(m.group(0))
            else:
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def match_brace(s, open_at):
    depth = 0
    for j in range(open_at, len(s)):
        if s[j] == "{":
            depth += 1
        elif s[j] == "}":
            depth -= 1
            if depth == 0:
                return j
    return len(s) - 1


def is_test_file(path):
    parts = path.split("/")
    return ("tests" in parts[:-1] or "benches" in parts[:-1] or "examples" in parts[:-1]
            or parts[-1] in ("tests.rs", "fuzz.rs", "testbench.rs") or parts[0] == "tests")


def test_ranges(s):
    ranges = []
    for m in re.finditer(r"#\[cfg\(test\)\]\s*(pub(\([^)]*\))?\s+)?mod\s+\w+\s*\{", s):
        open_at = m.end() - 1
        ranges.append((m.start(), match_brace(s, open_at)))
    return ranges


FN = re.compile(r"\bfn\s+(\w+)\s*(<[^{;]*?>)?\s*\(")


def functions(path):
    src = open(os.path.join(ROOT, path), encoding="utf-8", errors="replace").read()
    s = strip(src)
    skip = test_ranges(s)
    found = []
    for m in FN.finditer(s):
        if any(a <= m.start() <= b for a, b in skip):
            continue
        # the body: first `{` after the signature, unless a `;` comes first (trait decl)
        k = m.end()
        depth = 1
        while k < len(s) and depth:
            depth += {"(": 1, ")": -1}.get(s[k], 0)
            k += 1
        brace = s.find("{", k)
        semi = s.find(";", k)
        if brace < 0 or (0 <= semi < brace):
            continue
        end = match_brace(s, brace)
        first = s.count("\n", 0, m.start()) + 1
        last = s.count("\n", 0, end) + 1
        found.append((last - first + 1, path, first, m.group(1)))
    return found


def crate_of(path):
    parts = path.split("/")
    if parts[0] == "crates":
        return "/".join(parts[:2])
    return parts[0]


def module_map(files):
    """crate -> {module path tuple: file} for src/ files."""
    mods = {}
    for p in files:
        parts = p.split("/")
        if "src" not in parts:
            continue
        i = parts.index("src")
        crate = "/".join(parts[:i])
        rel = parts[i + 1:]
        if rel[0] == "bin":
            continue
        if rel[-1] in ("lib.rs", "main.rs") and len(rel) == 1:
            key = ()
        elif rel[-1] == "mod.rs":
            key = tuple(rel[:-1])
        else:
            key = tuple(rel[:-1]) + (rel[-1][:-3],)
        mods.setdefault(crate, {})[key] = p
    return mods


REF = re.compile(r"\b(crate|super)((?:::\w+)+)")
USE_GROUP = re.compile(r"\b(crate|super)((?:::\w+)*)::\{([^;]*?)\}", re.S)


def circles(files):
    mods = module_map(files)
    found = []
    for crate, table in mods.items():
        edges = {p: set() for p in table.values()}
        for key, p in table.items():
            s = strip(open(os.path.join(ROOT, p), encoding="utf-8", errors="replace").read())
            for a, b in test_ranges(s):
                s = s[:a] + " " * (b - a) + s[b:]
            targets = []
            for m in REF.finditer(s):
                targets.append((m.group(1), [x for x in m.group(2).split("::") if x]))
            for m in USE_GROUP.finditer(s):
                base = [x for x in m.group(2).split("::") if x]
                for item in re.split(r"[,\s]+", m.group(3)):
                    item = item.split("::")[0].strip()
                    if item and item not in ("self",) and re.match(r"\w+$", item):
                        targets.append((m.group(1), base + [item]))
            for kind, segs in targets:
                if kind == "crate":
                    path = segs
                else:
                    # `super` of module `key` (a file or a mod.rs alike) is
                    # its parent; each further `super` one more up.
                    up = list(key)[:-1]
                    while segs and segs[0] == "super":
                        segs = segs[1:]
                        up = up[:-1]
                    path = up + segs
                # longest prefix that is a module file
                best = None
                for n in range(len(path), 0, -1):
                    if tuple(path[:n]) in table:
                        best = tuple(path[:n])
                        break
                if not best:
                    continue
                q = table[best]
                if q != p and os.path.basename(q) not in ("lib.rs", "main.rs") and best != key[:len(best)]:
                    edges[p].add(q)
        if os.environ.get("LAYOUT_DEBUG") and os.environ["LAYOUT_DEBUG"] in crate:
            for k, v in edges.items():
                print("   edge", k, "->", sorted(v))
        # cycles: strongly connected components with more than one file
        index, low, stack, on, comps, counter = {}, {}, [], set(), [], [0]

        def visit(v):
            index[v] = low[v] = counter[0]
            counter[0] += 1
            stack.append(v)
            on.add(v)
            for w in edges[v]:
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
                    comps.append(sorted(comp))

        sys.setrecursionlimit(10000)
        for v in edges:
            if v not in index:
                visit(v)
        found.extend(comps)
    return found


def main():
    check = "--check" in sys.argv
    files = tracked_rs()
    lines = {}
    for p in files:
        n = sum(1 for _ in open(os.path.join(ROOT, p), encoding="utf-8", errors="replace"))
        lines[crate_of(p)] = lines.get(crate_of(p), 0) + n
    print("lines per crate (all .rs, tests included):")
    for c in sorted(lines):
        print(f"  {lines[c]:6d}  {c}")
    print(f"  {sum(lines.values()):6d}  total")
    fns = []
    for p in files:
        if not is_test_file(p):
            fns.extend(functions(p))
    fns.sort(reverse=True)
    print("longest non-test functions:")
    for n, p, line, name in fns[:12]:
        print(f"  {n:5d}  {p}:{line} {name}")
    over = [f for f in fns if f[0] > MAX_FN]
    print(f"functions over {MAX_FN} lines: {len(over)}")
    cyc = circles(files)
    print(f"import circles between files: {len(cyc)}")
    for c in cyc:
        print("  " + " <-> ".join(c))
    if check and (over or cyc):
        sys.exit(1)


if __name__ == "__main__":
    main()
