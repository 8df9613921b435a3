// The step's contact pipeline (World::step's first phase): the broad phase's
// candidate pairs (the Collider), the narrow phase over them in chunks with
// each block's face planes cached over a chunk's pairs, and the contact
// store's update with this step's sub-contacts, prepared for the solver
// (prepareContact). World owns the blocks, the collider and the store;
// ContactDetection owns the narrow phase's work arrays and the flush-joint
// faces of the fixed blocks.
#pragma once

#include "IntegratorSettings.hpp"
#include "dda/block/Block.hpp"
#include "dda/collider/Collider.hpp"
#include "dda/contact/Contact.hpp"

#include <cstddef>
#include <utility>
#include <vector>

namespace dda {

class StateWriter;
class StateReader;

// Diagonal of a block's bounding box [m].
double boundingDiagonal(const Block& block);

// The narrow phase's settings for a pair of blocks of bounding diagonals
// diagonalA and diagonalB [m], as World::step uses them: contact distance d0
// [m], length tolerance, entrance hysteresis and corner merge distance from the
// blocks' sizes, and the parallel-edge angle from the allowed step
// displacement [m] (0: the smallest angle tolerance).
DetectionSettings pairDetectionSettings(double diagonalA, double diagonalB, double contactDistance,
                                        double allowedDisplacement);

// The step's contact distance d0 [m]: IntegratorSettings::contactDistance, or
// without it contactDistanceFactor x the allowed displacement of a step [m].
double stepContactDistance(const IntegratorSettings& settings, double allowedDisplacement);

class ContactDetection {
public:
	// Broad and narrow phase; fills store with this step's sub-contacts (their
	// friction tangents x frictionScale) and stats with the phases' counts and
	// times (stats.contactDistance and allowedDisplacement are read).
	void detect(const std::vector<Block>& blocks, Collider& collider, ContactStore& store,
	            const IntegratorSettings& settings, double frictionScale, StepStatistics& stats);
	// Heap of the narrow phase's work arrays [bytes] (World::MemoryUse::narrowPhase).
	std::size_t memoryBytes() const;
	// Faces of fixed blocks covered by a flush neighbour, per block (empty for
	// a moving block); as the last detection left them.
	const std::vector<std::vector<char>>& internalFaces() const { return internalFaces_; }
	// Some fixed blocks moved and others did not (a prescribed motion of a
	// part of them, World::addBaseMotion): faces that were flush may be no
	// longer, so the next detection finds the flush faces and covers again.
	void fixedBlocksMoved() { internalFacesBlocks_ = coverDepthsBlocks_ = -1; }
	// Saving (World::writeState / readState): the flush-joint faces and the
	// block count they were computed for.
	void writeState(StateWriter& out) const;
	void readState(StateReader& in);

private:
	// One detection's inputs and outputs, as detect() was given them.
	struct Step {
		const std::vector<Block>& blocks;
		Collider& collider;
		ContactStore& store;
		const IntegratorSettings& settings;
		double frictionScale;
		StepStatistics& stats;
		bool threads;  // whether the chunks' loops run threaded
	};
	void findPairs(const std::vector<Block>& blocks, Collider& collider, bool reusePairs, StepStatistics& stats);
	void updateInternalFaces(const std::vector<Block>& blocks);
	// covers_ of the fixed blocks (markInternalFaces), their flags in `flags`.
	void markFixedBlocks(const std::vector<Block>& blocks, std::vector<std::vector<char>>& flags);
	// Before the first chunk (and after the per-block diagonals): each
	// block's last chunk, the planes' free list and the chunk's pooled results.
	void startChunks(const std::vector<Block>& blocks);
	// The narrow phase of pairs_[begin, begin + count) (chunk number `chunk`),
	// its contacts into the store in pair order.
	void detectChunk(Step& step, int begin, int count, int chunk);
	// An entry of planes_ for each block of the pairs [begin, next) that has none.
	void claimPlanes(int begin, int next);
	// The entries of the blocks of pairs [begin, next) whose last chunk is `chunk`.
	void releasePlanes(int begin, int next, int chunk);
	// After a chunk's pair loop, in pair order: its counts, the found pairs'
	// entrances, where each one's contacts go (pairFirst_, from the store's
	// contact firstContact on: the chunk's first), the store's contacts
	// trimmed or grown to the chunk's end, and contactsPerPair_.
	void takeChunk(Step& step, int begin, int count, int firstContact);
	// A found pair's sub-contacts, into the store's contacts from `first` on
	// (each takes over its predecessor's history), with the pair's contact
	// area [m^2], prepared for the solver; returns how many have friction.
	long storePair(Step& step, int a, int b, const PairContacts& pair, double area, int first);
	static double contactArea(const PairContacts& pair);

	std::vector<std::pair<int, int>> pairs_;
	// The narrow phase runs the candidate pairs in chunks (kPairChunk in
	// ContactDetection.cpp), so what it holds is sized by a chunk, not by the
	// scene. Per pair of the current chunk, its result (a pool: each entry
	// keeps its contacts' capacity from chunk to chunk and step to step, so
	// detection allocates only while it grows), whether it is in contact, and
	// its work.
	std::vector<PairContacts> pairResults_;
	std::vector<char> pairFound_;
	std::vector<NarrowPhaseWork> pairWork_;
	std::vector<double> diagonals_;  // per block, bounding-box diagonal of this step [m]
	// Entries for the face planes, edge data and bounding box (BlockPlanes) of
	// the blocks of the current chunk's pairs: a block's are built before the
	// parallel pair loop of the first chunk with a pair of it (planeBlocks_
	// lists those of this chunk), read-only in the loops, and its entry goes
	// back to freePlanes_ after its last chunk (lastChunk_). planes_ is only
	// grown, so its entries keep their vectors' capacity.
	std::vector<BlockPlanes> planes_;
	std::vector<int> freePlanes_;
	std::vector<int> planeBlocks_;
	std::vector<int> planeSlot_;  // per block: its entry of planes_, -1 when none
	std::vector<int> lastChunk_;  // per block: the last chunk with a pair of it (this step)
	// Faces of fixed blocks covered by a flush neighbour (BlockGeometry::internalFaces).
	std::vector<std::vector<char>> internalFaces_;
	int internalFacesBlocks_ = -1;  // block count when internalFaces_ was computed
	// Per fixed block and face, what covers it: how far its flush neighbour
	// surely reaches past a covered face, and the neighbour's other planes
	// (BlockGeometry::covers). Not saved: computed again
	// from the fixed blocks (which never move) after a load, the same doubles.
	std::vector<std::vector<FaceCover>> covers_;
	int coverDepthsBlocks_ = -1;  // block count when covers_ was computed
	std::vector<double> pairArea_;  // per pair of the chunk, its contact area [m^2] (found pairs)
	double contactsPerPair_ = 1;    // the last chunk's contacts per candidate pair (its estimate for the next)
	std::vector<int> pairFirst_;    // per found pair of the chunk, where its contacts start among the chunk's
};

}  // namespace dda
