// Double-float arithmetic (a value is vec2(hi, lo) with |lo| ≤ ulp(hi)/2), after Dekker (1971),
// Knuth's two-sum and DSFUN90 (Bailey). Every temporary is `precise`: without it a compiler may
// reassociate (s − a) − b to 0 or fuse a·b − p into an FMA and the low parts vanish. Two-prod is
// Dekker's split, not fma(): fma would be exact too, but we cannot rely on a device's fma being
// fused, and an unfused fma silently drops the low part. The split constant (2^12 + 1 for float)
// arrives at run time so no compiler can fold the split.

// s + e = a + b exactly (Knuth; no condition on |a| vs |b|).
vec2 twoSum(float a, float b) {
  precise float s = a + b;
  precise float v = s - a;
  precise float e = (a - (s - v)) + (b - v);
  return vec2(s, e);
}

// s + e = a + b exactly when |a| ≥ |b| (or a = 0).
vec2 quickTwoSum(float a, float b) {
  precise float s = a + b;
  precise float e = b - (s - a);
  return vec2(s, e);
}

// a = hi + lo with hi holding the upper 12 bits (Dekker).
vec2 splitFloat(float a, float splitter) {
  precise float t = splitter * a;
  precise float hi = t - (t - a);
  precise float lo = a - hi;
  return vec2(hi, lo);
}

// p + e = a · b exactly (Dekker), barring overflow of splitter · a.
vec2 twoProd(float a, float b, float splitter) {
  precise float p = a * b;
  vec2 as = splitFloat(a, splitter);
  vec2 bs = splitFloat(b, splitter);
  precise float e = ((as.x * bs.x - p) + as.x * bs.y + as.y * bs.x) + as.y * bs.y;
  return vec2(p, e);
}

vec2 dfAdd(vec2 a, vec2 b) {
  vec2 s = twoSum(a.x, b.x);
  vec2 t = twoSum(a.y, b.y);
  precise float s_lo = s.y + t.x;
  s = quickTwoSum(s.x, s_lo);
  precise float s_lo2 = s.y + t.y;
  return quickTwoSum(s.x, s_lo2);
}

vec2 dfMul(vec2 a, vec2 b, float splitter) {
  vec2 p = twoProd(a.x, b.x, splitter);
  precise float cross_terms = a.x * b.y + a.y * b.x;
  precise float p_lo = p.y + cross_terms;
  return quickTwoSum(p.x, p_lo);
}
