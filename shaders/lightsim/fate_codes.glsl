// Fate codes of a patch after ALGORITHM.md step 5 (analysis), shared by the analysis, ledger and
// compaction passes.
const int FATE_NONE = 0;     // no patch at this slot
const int FATE_KEEP = 1;     // count 1
const int FATE_SPLIT = 2;    // count 4
const int FATE_EXITED = 3;   // count 0: outside the box, heading away
const int FATE_FLUX = 4;     // count 0: max(Φ) under the threshold
const int FATE_FOLDED = 5;   // count 0: N·d ≤ 0 (caustic singularity)
const int FATE_DEPTH = 6;    // count 0: needs a split beyond max_depth

float fateCount(int fate) { return fate == FATE_KEEP ? 1.0 : (fate == FATE_SPLIT ? 4.0 : 0.0); }
