"""Independent reference for the bundle gap generator (SplitMix64 -> xoshiro256**,
uniform, Marsaglia polar normal with the module's own ln). Python floats are IEEE
doubles with correctly rounded + - * / sqrt, so the results must match Rust bit for bit."""
import math, struct
M = (1 << 64) - 1
def splitmix(state):
    state = (state + 0x9E3779B97F4A7C15) & M
    z = state
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & M
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & M
    return state, z ^ (z >> 31)
rotl = lambda x, k: ((x << k) | (x >> (64 - k))) & M
class Rng:
    def __init__(self, seed):
        self.s = []
        for _ in range(4):
            seed, z = splitmix(seed); self.s.append(z)
    def next(self):
        s = self.s
        r = (rotl((s[1] * 5) & M, 7) * 9) & M
        t = (s[1] << 17) & M
        s[2] ^= s[0]; s[3] ^= s[1]; s[1] ^= s[2]; s[0] ^= s[3]; s[2] ^= t; s[3] = rotl(s[3], 45)
        return r
    def uniform(self): return (self.next() >> 11) * (1.0 / 9007199254740992.0)
    def uniform_open_zero(self): return ((self.next() >> 11) + 1) * (1.0 / 9007199254740992.0)
    def normal(self):
        while True:
            a = 2.0 * self.uniform() - 1.0; b = 2.0 * self.uniform() - 1.0
            s = a * a + b * b
            if 0.0 < s < 1.0: return a * math.sqrt(-2.0 * ln(s) / s)
    def normal_above(self, alpha):
        if alpha <= 0:
            while True:
                z = self.normal()
                if z >= alpha: return z
        rate = 0.5 * (alpha + math.sqrt(alpha * alpha + 4.0))
        while True:
            z = alpha - ln(self.uniform_open_zero()) / rate
            e = z - rate
            if ln(self.uniform_open_zero()) <= -0.5 * e * e: return z
def ln(x):
    e = 0
    if x < 2.2250738585072014e-308: x *= 18014398509481984.0; e = -54
    bits = struct.unpack('<Q', struct.pack('<d', x))[0]
    e += ((bits >> 52) & 0x7ff) - 1023
    m = struct.unpack('<d', struct.pack('<Q', (bits & 0x000fffffffffffff) | (1023 << 52)))[0]
    if m > math.sqrt(2.0): m *= 0.5; e += 1
    t = (m - 1.0) / (m + 1.0); t2 = t * t; s = 0.0
    for k in reversed(range(12)): s = s * t2 + 1.0 / (2 * k + 1)
    return e * 0.6931471805599453 + 2.0 * t * s
st, z = splitmix(0); print("splitmix(0) first", hex(z))
r = Rng(42); print("state", [hex(x) for x in r.s]); print("raw", [hex(r.next()) for _ in range(4)])
r = Rng(42); print("uniform", [repr(r.uniform()) for _ in range(3)])
r = Rng(42); print("normal", [repr(r.normal()) for _ in range(4)])
r = Rng(42); print("above(1.5)", [repr(r.normal_above(1.5)) for _ in range(3)])
for x in [0.5, 1e-300, 5e-324, 0.123, 3.0]: print("ln", x, repr(ln(x)), repr(math.log(x)))
