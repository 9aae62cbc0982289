// Histogram pyramid traversal (ALGORITHM.md step 6; Ziegler et al. 2006, with the RGBA node layout
// of Dyken et al. 2008). Include as
//   #include "lightsim/histo_pyramid.glsl"
// in a pass compiled with HistoPyramid::defines() (lightsim/histo_pyramid.h), which defines
//   HP_LEVELS  the number of levels above the base: log2 of the base side (1 for a 1×1 base).
//
// The pyramid is ONE RGBA32F texture with mip levels 0 .. HP_LEVELS − 1 (HistoPyramid::bind(unit)).
// Texel t of mip m is node t of pyramid level m + 1 and holds the sums of its four children at
// level m (level 0 = the counts), in child order: .x (0,0), .y (1,0), .z (0,1), .w (1,1). The top,
// mip HP_LEVELS − 1, is 1×1: its four components add up to the total. Read it with texelFetch only.
//
// Slots: list index k ↔ texel hpSlotTexel(k) (Morton / Z-order: x from the even bits of k, y from
// the odd ones; the same placement as lightsim/patch.glsl's mortonTexel). The descent visits the
// base in exactly this order, so the expanded list is in the CPU twin's prefix-sum order.
//
// Typical compaction pass (one fragment per output slot):
//   ivec2 outTexel = ivec2(gl_FragCoord.xy);
//   int k = hpTexelSlot(outTexel);
//   if (k >= uTotal) discard;                 // uTotal: HistoPyramid::readTotal(), or hpTotal()
//   int j;
//   ivec2 source = hpFind(uPyramid, k, j);    // source texel in the base, j in [0, count)
//
// The helpers are plain int arithmetic; slots and counts must stay below 2^24 (R32F is exact there).
#ifndef LIGHTSIM_HISTO_PYRAMID_GLSL
#define LIGHTSIM_HISTO_PYRAMID_GLSL

// Spreads the low 16 bits of v to the even bit positions.
int hpPart1By1(int v) {
  v &= 0x0000ffff;
  v = (v | (v << 8)) & 0x00ff00ff;
  v = (v | (v << 4)) & 0x0f0f0f0f;
  v = (v | (v << 2)) & 0x33333333;
  v = (v | (v << 1)) & 0x55555555;
  return v;
}

// Gathers the even bits of v into the low 16 bits.
int hpCompact1By1(int v) {
  v &= 0x55555555;
  v = (v | (v >> 1)) & 0x33333333;
  v = (v | (v >> 2)) & 0x0f0f0f0f;
  v = (v | (v >> 4)) & 0x00ff00ff;
  v = (v | (v >> 8)) & 0x0000ffff;
  return v;
}

// List index (slot) → texel, and back. Valid at every pyramid level: the children of node t at the
// level below are the slots 4·hpTexelSlot(t) + 0..3, in the child order (0,0), (1,0), (0,1), (1,1).
ivec2 hpSlotTexel(int slot) { return ivec2(hpCompact1By1(slot), hpCompact1By1(slot >> 1)); }
int hpTexelSlot(ivec2 texel) { return hpPart1By1(texel.x) | (hpPart1By1(texel.y) << 1); }

#ifdef HP_LEVELS

// The total of the counts (the four components of the top texel), as int.
int hpTotal(sampler2D pyramid) {
  ivec4 top = ivec4(texelFetch(pyramid, ivec2(0), HP_LEVELS - 1));
  return (top.x + top.y) + (top.z + top.w);
}

// Output slot k (0 ≤ k < total) → the base texel s whose count range holds k, and the sub-index
// j = k − (sum of the counts before s), 0 ≤ j < count(s). Descends from the top in the fixed child
// order 0: (0,0), 1: (1,0), 2: (0,1), 3: (1,1): one fetch a level, HP_LEVELS fetches in all. For
// k ≥ total the result is meaningless (the caller discards those slots).
ivec2 hpFind(sampler2D pyramid, int k, out int subIndex) {
  ivec2 node = ivec2(0);
  for (int level = HP_LEVELS - 1; level >= 0; --level) {
    ivec4 c = ivec4(texelFetch(pyramid, node, level));
    // passed.i = 1 when k lies beyond children 0..i. (Made prefix-monotone defensively: the texels
    // on the path were all written by this build, with 0 for children beyond the live slots.)
    ivec3 passed = ivec3(lessThanEqual(ivec3(c.x, c.x + c.y, c.x + c.y + c.z), ivec3(k)));
    passed.y *= passed.x;
    passed.z *= passed.y;
    int child = passed.x + passed.y + passed.z;
    k -= c.x * passed.x + c.y * passed.y + c.z * passed.z;
    node = 2 * node + ivec2(child & 1, child >> 1);
  }
  subIndex = k;
  return node;
}

// The same, returning the source's slot (list index) instead of its texel.
int hpFindSlot(sampler2D pyramid, int k, out int subIndex) { return hpTexelSlot(hpFind(pyramid, k, subIndex)); }

#endif  // HP_LEVELS
#endif  // LIGHTSIM_HISTO_PYRAMID_GLSL
