#!/usr/bin/env python3
"""Map every control point of a G+Smo XML file (the <coefs geoDim="2"> blocks) by
x -> (ax + s x, ay + s y), in double precision like jq; everything else is copied.

    python3 scripts/similar_xml.py IN.xml AX AY S > OUT.xml

Used by scripts/invariance.sh for the multipatch layouts."""
import re
import sys

src, ax, ay, s = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])


def block(m):
    out = []
    for line in m.group(2).split("\n"):
        v = line.split()
        if len(v) == 2:
            x, y = float(v[0]), float(v[1])
            line = f"{x * s + ax!r} {y * s + ay!r} "
        out.append(line)
    return m.group(1) + "\n".join(out) + m.group(3)


text = open(src).read()
sys.stdout.write(re.sub(r'(<coefs geoDim="2">)(.*?)(</coefs>)', block, text, flags=re.S))
