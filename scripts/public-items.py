#!/usr/bin/env python3
"""Counts the public items of the core (`crates/core/src`) and lists those no user outside
it names: a line `pub fn|struct|enum|trait|type|const|static|union NAME` (not `pub(crate)`,
not inside a `#[cfg(test)]` file `tests.rs`) is a public item; it is *used outside* when
NAME occurs as a word in another crate, an integration test, an example, a bench, a fuzz
target, the facade package `src/`, the README (a doctest) or a code block of a doc comment
of the core (a doctest), or in a `pub use` of the core (a re-export).

    python3 scripts/public-items.py          # the count
    python3 scripts/public-items.py --unused # FILE:LINE NAME of every item no one outside names
"""
import os, re, sys

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
core = os.path.join(root, "crates/core/src")
ITEM = re.compile(r"^\s*pub\s+(?:const\s+fn|unsafe\s+fn|async\s+fn|fn|struct|enum|trait|type|const|static|union)\s+([A-Za-z_]\w*)")
WORD = re.compile(r"[A-Za-z_]\w*")

def rs_files(top):
    for d, _, fs in os.walk(top):
        if "/target" in d:
            continue
        for f in fs:
            if f.endswith(".rs"):
                yield os.path.join(d, f)

used = set()
outside = [os.path.join(root, p) for p in ("crates/cli", "crates/viewer", "crates/python", "crates/gpu", "crates/mesh",
                                           "tests", "examples", "fuzz", "src", "crates/core/tests",
                                           "crates/core/benches", "crates/core/examples")]
for top in outside:
    for f in rs_files(top):
        used.update(WORD.findall(open(f, encoding="utf-8").read()))
used.update(WORD.findall(open(os.path.join(root, "README.md"), encoding="utf-8").read()))

items = []
for f in sorted(rs_files(core)):
    text = open(f, encoding="utf-8").read().splitlines()
    fence = False
    for i, line in enumerate(text, 1):
        s = line.strip()
        if s.startswith("///") or s.startswith("//!"):
            body = s[3:].strip()
            if body.startswith("```"):
                fence = not fence
            elif fence:
                used.update(WORD.findall(body))
            continue
        if re.match(r"^\s*pub\s+use\b", line):
            # a re-export (possibly over several lines)
            j, stmt = i - 1, ""
            while j < len(text):
                stmt += text[j]
                if ";" in text[j]:
                    break
                j += 1
            used.update(WORD.findall(stmt))
        if os.path.basename(f) == "tests.rs" or "/tests/" in f:
            continue
        m = ITEM.match(line)
        if m:
            items.append((os.path.relpath(f, root), i, m.group(1)))

if "--unused" in sys.argv:
    for f, i, n in items:
        if n not in used:
            print(f"{f}:{i} {n}")
else:
    unused = sum(1 for _, _, n in items if n not in used)
    print(f"public items in crates/core/src: {len(items)}; named by no user outside the core: {unused}")
