// What a broad phase reports of one findPairs call (Collider.hpp).
#pragma once

namespace dda {

// Counters of one findPairs call (they describe that call only).
struct BroadPhaseStatistics {
	long candidatePairs = 0;  // block pairs handed to the narrow phase
	long shellPairs = 0;      // overlapping bounding-volume pairs found (MSC: shell pairs, as boxes and in frames)
	long shellTests = 0;      // bounding-volume comparisons made (cached pairs re-checked and MSC's frame tests included)
	long shells = 0;          // bounding volumes (DESS, NBS: one per block; AllPairs: none)
	long shellUpdates = 0;    // bounding volumes recomputed from corners this call
	// The narrow phase's "sub-unit loops" (Wu et al. 2014, Sec. 4.2): over the
	// candidate pairs (a, b), Va x Fb + Vb x Fa + Ea x Eb, with V, E, F the
	// vertices, edges and faces each block offers the pair (MSC: the linked
	// sub-units of the overlapping shells; other strategies: all of them).
	long subUnitPairs = 0;
	// Candidate-pair reuse (DESS's and MSC's Verlet caches; 0 for other strategies).
	long broadPhaseSkipped = 0;  // 1 when no sort-and-sweep was made this call (pairs from the cache)
	long pairsReused = 0;        // cached pairs re-checked instead of searched for
	long blocksResearched = 0;   // blocks searched against the others this call (all of them on a full search)
};

}  // namespace dda
