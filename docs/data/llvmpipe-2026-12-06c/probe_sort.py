# Adversarial check of `texflow sort --variant blocked` against a CPU argsort by (key order, index).
# usage: python3 probe_sort.py TEXFLOW_BINARY PATTERNS SIZES
#   e.g. python3 probe_sort.py ./target/release/texflow random,sorted,reversed,equal,few,special,sawtooth 1025,4096,65537,262144,300000,1048576,1500000
# (the second run: special,reversed,few 2049,8193,131073,524289,2097152,4194305). Works in a temporary folder.
import struct, random, subprocess, sys, os, tempfile
D = tempfile.mkdtemp()
T = sys.argv[1]
def write_npy(path, vals):
    hdr = "{'descr': '<f4', 'fortran_order': False, 'shape': (%d,), }" % len(vals)
    pad = 64 - (10 + len(hdr) + 1) % 64
    hdr = hdr + ' ' * pad + '\n'
    with open(path, 'wb') as f:
        f.write(b'\x93NUMPY\x01\x00' + struct.pack('<H', len(hdr)) + hdr.encode())
        f.write(struct.pack('<%df' % len(vals), *vals))
def read_npy(path, fmt):
    b = open(path, 'rb').read()
    hl = struct.unpack('<H', b[8:10])[0]
    data = b[10 + hl:]
    n = len(data) // 4
    return list(struct.unpack('<%d%s' % (n, fmt), data))
def bits(x):
    return struct.unpack('<I', struct.pack('<f', x))[0]
def order(x):
    u = bits(x)
    if u == 0x80000000: u = 0
    if (u & 0x7fffffff) > 0x7f800000: u = 0x7fc00000
    return (~u) & 0xffffffff if u & 0x80000000 else u | 0x80000000
def keys(pattern, n, rnd):
    if pattern == 'random': return [rnd.uniform(-1e3, 1e3) for _ in range(n)]
    if pattern == 'sorted': return [float(i) for i in range(n)]
    if pattern == 'reversed': return [float(n - i) for i in range(n)]
    if pattern == 'equal': return [3.5] * n
    if pattern == 'few': return [float(rnd.randrange(4)) for _ in range(n)]
    if pattern == 'special':
        sp = [float('inf'), float('-inf'), float('nan'), 0.0, -0.0, 1e-40, -1e-40, 3.4e38, -3.4e38]
        return [rnd.choice(sp) if rnd.random() < 0.3 else rnd.uniform(-5, 5) for _ in range(n)]
    if pattern == 'sawtooth': return [float(i % 1000) for i in range(n)]
bad = 0
PATTERNS = sys.argv[2].split(',')
SIZES = [int(x) for x in sys.argv[3].split(',')]
rnd = random.Random(1)
for n in SIZES:
    for pattern in PATTERNS:
        k = keys(pattern, n, rnd)
        # float32 round trip
        k = list(struct.unpack('<%df' % n, struct.pack('<%df' % n, *k)))
        write_npy(os.path.join(D, 'in.npy'), k)
        r = subprocess.run([T, 'sort', '--variant', 'blocked', '--input', os.path.join(D, 'in.npy'), '--output', os.path.join(D, 'out.npy'), '--ids', os.path.join(D, 'ids.npy'), '-q'], capture_output=True, text=True)
        if r.returncode != 0:
            print('FAIL rc', n, pattern, r.stderr[:300]); bad += 1; continue
        ids = read_npy(os.path.join(D, 'ids.npy'), 'i')
        want = sorted(range(n), key=lambda i: (order(k[i]), i))
        ok = ids == want
        if not ok: bad += 1
        print(n, pattern, 'ok' if ok else 'MISMATCH')
print('bad', bad)
