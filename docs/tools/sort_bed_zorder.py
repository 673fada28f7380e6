# Sort bed_rocks.csv rows along a Z-order curve of the rock centres (grid cell = 0.11 m from the origin),
# as crates/rockfill/src/spatial_order.rs numbers freshly generated rocks. Usage: python3 docs/tools/sort_bed_zorder.py IN OUT (the A/B of docs/speed.md)
import sys
def spread(v):
    out = 0
    for b in range(21):
        out |= ((v >> b) & 1) << (3 * b)
    return out
lines = open(sys.argv[1]).read().splitlines()
head = [l for l in lines if l.startswith('#') or l.startswith('rock,')]
rows = [l for l in lines if l and not (l.startswith('#') or l.startswith('rock,'))]
def key(l):
    f = l.split(',')
    c = [max(0, int(float(f[k]) // 0.11)) for k in (2, 3, 4)]
    return spread(c[0]) | (spread(c[1]) << 1) | (spread(c[2]) << 2)
rows.sort(key=key)
open(sys.argv[2], 'w').write('\n'.join(head + rows) + '\n')
