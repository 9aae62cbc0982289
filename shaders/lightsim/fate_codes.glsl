// Fate codes of a patch after ALGORITHM.md step 5 (analysis), shared by the analysis, ledger and
// compaction passes. Codes ≥ FATE_SPLIT are what the ledger records; codes ≥ FATE_EXITED are dead.
const int FATE_NONE = 0;      // no patch at this slot
const int FATE_KEEP = 1;      // count 1
const int FATE_SPLIT = 2;     // count 4: 2×2 split
const int FATE_SPLIT_U = 3;   // count 2: 1×2 split halving u (edges x0x1, x3x2)
const int FATE_SPLIT_V = 4;   // count 2: 1×2 split halving v (edges x1x2, x0x3)
const int FATE_EXITED = 5;    // count 0: outside the box, heading away
const int FATE_FLUX = 6;      // count 0: max(Φ) under the threshold
const int FATE_FOLDED = 7;    // count 0: N·d ≤ 0 (caustic singularity)
const int FATE_DEPTH = 8;     // count 0: needs a split beyond max_depth (or torn)
const int FATE_RECEIVED = 9;  // count 0: reached the receiver plane (its flux goes to the map)
const int FATE_BLOCKED = 10;  // count 0: stopped by an opaque surface (≥ 2 corners)
const int FATE_TRAPPED = 11;  // count 0: trapped by total internal reflection (its flux: unfinished)

// The analysis stores a fate with two flags in one float (ledger A's w): code = fate +
// FATE_SPAWNS (the reflected wavefront is followed as a new patch, one more slot) + FATE_ROLLED_BACK
// (the step was undone and the patch splits before it crosses).
const int FATE_SPAWNS = 16;
const int FATE_ROLLED_BACK = 32;
int fateOf(int code) { return code & 15; }
bool fateSpawns(int code) { return (code & FATE_SPAWNS) != 0; }
bool fateRolledBack(int code) { return (code & FATE_ROLLED_BACK) != 0; }

bool fateSplits(int fate) { return fate >= FATE_SPLIT && fate <= FATE_SPLIT_V; }
float fateCount(int fate) {
  return fate == FATE_KEEP ? 1.0 : fate == FATE_SPLIT ? 4.0 : fateSplits(fate) ? 2.0 : 0.0;
}
// Slots of the new list a stored code takes.
float codeCount(int code) { return fateCount(fateOf(code)) + (fateSpawns(code) ? 1.0 : 0.0); }
// Children along u and v of a split fate: (2,2), (2,1) or (1,2).
ivec2 fateSplitCells(int fate) {
  return ivec2(fate == FATE_SPLIT_V ? 1 : 2, fate == FATE_SPLIT_U ? 1 : 2);
}
