#include "ContactDetection.hpp"

#include "ContactEquations.hpp"
#include "dda/core/StateStream.hpp"
#include "StepClock.hpp"
#include "dda/geometry/InternalFaces.hpp"
#include "dda/geometry/ProjectedHull.hpp"
#include "dda/core/CapacityBytes.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace dda {

namespace {
// Candidate pairs per chunk of the narrow phase (ContactDetection::detect). It
// holds the results of one chunk's pairs and the planes of about one chunk's
// blocks, so its memory no longer grows with the scene (50,000 slender blocks
// with MSC: 17 MB instead of 81; 10 MB with 4,096). Each chunk is an OpenMP
// team with a barrier inside, and on a loaded machine each can wait a
// scheduler slice: with 2 threads on a loaded 2-core machine, 10,000 slender
// blocks under DESS (64,000 pairs) had a narrow phase up to twice as long
// with chunks of 2,048, 1.5 times with 4,096, and with 8,192 no longer than
// without chunks.
constexpr int kPairChunk = 8192;
// A chunk's contacts are made ahead for this x the last chunk's contacts per
// pair [-] (ContactDetection::detectChunk): a few too many cost their
// making, too few a serial pass for the rest.
constexpr double kContactEstimateMargin = 1.1;
// A pair keeps its entrance feature only while that feature ties with the
// best axis (within the length tolerance; chooseFace prefers the previous
// face among ties, so the normal does not flip between equal faces from step
// to step). It used to be kept while within 0.1 d0 of the best axis (Shi's
// rule that a contact keeps its entrance face), up to 12.5 mm for a 1 m cube
// scene: the kept face's corners then lay deeper below its plane than the
// blocks overlapped, and their penalty springs stored energy no motion had
// put there (a stiff cube landing on another: a 0.43 mm corner contact, 363
// kJ, with the cubes 1.8 um into each other; and with that depth bounded,
// sub-contacts of the kept face that vanished let pairs sink and come back
// deeper, 73% of a 30-cube pile's largest energy change added between
// steps). Physical argument: a sub-contact's gap is a distance along the
// pair's contact normal, and the normal that measures how far two convex
// blocks overlap is the best separating axis; a face kept past it measures a
// depth no translation of the blocks removes.
constexpr double kEntranceHysteresis = 0.0;
// Corners of two blocks closer than this fraction of the smaller block's
// diagonal make one contact point (DetectionSettings::cornerMergeDistance).
constexpr double kCornerMergeFraction = 1e-3;
// Largest angle [rad] below which two edges count as parallel (about 3 degrees).
constexpr double kMaxParallelAngleTolerance = 0.05;
}  // namespace

double boundingDiagonal(const Block& block) {
	Eigen::AlignedBox3d box;
	for (const Vector3& x : block.vertices) box.extend(x);
	return box.diagonal().norm();
}

DetectionSettings pairDetectionSettings(double diagonalA, double diagonalB, double contactDistance,
                                        double allowedDisplacement) {
	DetectionSettings detection;
	detection.contactDistance = contactDistance;
	detection.lengthTolerance = kDefaultRelativeLengthTolerance * std::max(diagonalA, diagonalB);
	detection.hysteresis = std::max(kEntranceHysteresis * contactDistance, detection.lengthTolerance);
	detection.cornerMergeDistance = kCornerMergeFraction * std::min(diagonalA, diagonalB);
	// Edges closer to parallel than a block can turn in one step have no
	// stable crossing point: their contact is the vertex contacts at their
	// ends. The turn per step is at most the allowed displacement over the
	// half diagonal.
	detection.angleTolerance = std::clamp(2 * allowedDisplacement / std::min(diagonalA, diagonalB),
	                                      kDefaultParallelAngleTolerance, kMaxParallelAngleTolerance);
	return detection;
}

double stepContactDistance(const IntegratorSettings& settings, double allowedDisplacement) {
	return settings.contactDistance > 0 ? settings.contactDistance
	                                    : settings.contactDistanceFactor * allowedDisplacement;
}

void ContactDetection::detect(const std::vector<Block>& blocks, Collider& collider, ContactStore& store,
                              const IntegratorSettings& settings, double frictionScale, StepStatistics& stats) {
	findPairs(blocks, collider, settings.reuseCandidatePairs, stats);
	const auto phase = Clock::now();
	const double cpu = processCpuSeconds();
	const int blockCount = static_cast<int>(blocks.size());
	// The store's turn-over (the contact store's work, timed with the narrow
	// phase) and the blocks' diagonals are independent serial passes: one
	// thread each.
#pragma omp parallel sections if (blockCount >= kMinBlocksForThreads)
	{
#pragma omp section
		store.beginStep();
#pragma omp section
		{
			diagonals_.resize(blocks.size());
			for (int b = 0; b < blockCount; ++b) diagonals_[b] = boundingDiagonal(blocks[b]);
		}
	}
	if (internalFacesBlocks_ != blockCount) {
		updateInternalFaces(blocks);
	} else if (coverDepthsBlocks_ != blockCount) {  // after a load: the flags came with the state
		std::vector<std::vector<char>> flags;
		markFixedBlocks(blocks, flags);
	}
	const int pairCount = static_cast<int>(pairs_.size());
	// Threads by the step's pair count, not the chunk's: a small scene stays
	// serial, and a large one's chunks (all but perhaps its last) are large.
	Step step{blocks, collider, store, settings, frictionScale, stats, pairCount >= kMinPairsForThreads};
	startChunks(blocks);
	for (int begin = 0, chunk = 0; begin < pairCount; begin += kPairChunk, ++chunk)
		detectChunk(step, begin, std::min(kPairChunk, pairCount - begin), chunk);
	stats.contacts = static_cast<int>(store.contacts().size());
	stats.timeNarrowPhase = secondsSince(phase);
	stats.cpuNarrowPhase = processCpuSeconds() - cpu;
}

void ContactDetection::findPairs(const std::vector<Block>& blocks, Collider& collider, bool reusePairs,
                                 StepStatistics& stats) {
	const auto phase = Clock::now();
	const double cpu = processCpuSeconds();
	BroadPhaseStatistics broad;
	collider.setPairReuse(reusePairs);
	collider.findPairs(blocks, stats.contactDistance, pairs_, broad);
	stats.candidatePairs = broad.candidatePairs;
	stats.shellPairs = broad.shellPairs;
	stats.shellTests = broad.shellTests;
	stats.shells = broad.shells;
	stats.shellUpdates = broad.shellUpdates;
	stats.subUnitPairs = broad.subUnitPairs;
	stats.broadPhaseSkipped = broad.broadPhaseSkipped;
	stats.pairsReused = broad.pairsReused;
	stats.blocksResearched = broad.blocksResearched;
	for (const auto& [a, b] : pairs_) stats.fixedPairsSearched += blocks[a].fixed && blocks[b].fixed;
	stats.timeBroadPhase = secondsSince(phase);
	stats.cpuBroadPhase = processCpuSeconds() - cpu;
}

// Fixed blocks never move, and the parts of a concave block move by one
// affine map (the faces they share stay shared), so this runs only when
// blocks are added.
void ContactDetection::markFixedBlocks(const std::vector<Block>& blocks, std::vector<std::vector<char>>& flags) {
	std::vector<PlacedPolyhedron> fixed(blocks.size());
	for (std::size_t b = 0; b < blocks.size(); ++b)
		if (blocks[b].fixed) fixed[b] = PlacedPolyhedron{blocks[b].shape.get(), &blocks[b].vertices};
	markInternalFaces(fixed, kDefaultRelativeLengthTolerance, kDefaultParallelAngleTolerance, flags, &covers_);
	coverDepthsBlocks_ = static_cast<int>(blocks.size());
}

void ContactDetection::updateInternalFaces(const std::vector<Block>& blocks) {
	markFixedBlocks(blocks, internalFaces_);
	// The faces the parts of a moving concave block share (a fixed one's are
	// marked above with every fixed block).
	std::vector<std::vector<char>> partFaces;
	for (std::size_t b = 0; b < blocks.size(); ++b) {
		if (blocks[b].fixed || blocks[b].partCount == 1 || blocks[b].body >= 0) continue;
		std::vector<PlacedPolyhedron> parts;
		for (int p = 0; p < blocks[b].partCount; ++p)
			parts.push_back(PlacedPolyhedron{blocks[b + p].shape.get(), &blocks[b + p].vertices});
		markInternalFaces(parts, kDefaultRelativeLengthTolerance, kDefaultParallelAngleTolerance, partFaces);
		for (int p = 0; p < blocks[b].partCount; ++p)
			if (std::find(partFaces[p].begin(), partFaces[p].end(), 1) != partFaces[p].end())
				internalFaces_[b + p] = std::move(partFaces[p]);
	}
	internalFacesBlocks_ = static_cast<int>(blocks.size());
}

void ContactDetection::startChunks(const std::vector<Block>& blocks) {
	const int pairCount = static_cast<int>(pairs_.size());
	// Each block's planes are built once, before the first chunk with a pair
	// of it, and kept until its last such chunk (lastChunk_; only the entries
	// of blocks in a pair are read). Built again in each chunk instead, they
	// would be built 1.1 times per block on 50,000 slender blocks with MSC
	// and 2.4 times with DESS (its pairs by block index: a block's pairs as
	// the second block spread over several chunks), at about 2 us per block,
	// a third of an MSC pair. Kept, the planes held at once are about those
	// of one chunk's blocks when the pairs come roughly in space order (MSC's
	// shells; DESS's when block indices follow space, as there), and never
	// more than those of the blocks in a pair. planeSlot_ and freePlanes_ are
	// set whole here (cheap) so that nothing of an interrupted step survives.
	lastChunk_.resize(blocks.size());
	for (int p = 0; p < pairCount; ++p) lastChunk_[pairs_[p].first] = lastChunk_[pairs_[p].second] = p / kPairChunk;
	planeSlot_.assign(blocks.size(), -1);
	freePlanes_.clear();
	for (int k = static_cast<int>(planes_.size()) - 1; k >= 0; --k) freePlanes_.push_back(k);
	const int chunkCapacity = std::min(pairCount, kPairChunk);
	if (static_cast<int>(pairResults_.size()) < chunkCapacity) pairResults_.resize(chunkCapacity);
	pairFound_.resize(chunkCapacity);
	pairWork_.resize(chunkCapacity);
	pairArea_.resize(chunkCapacity);
	pairFirst_.resize(chunkCapacity);
}

void ContactDetection::claimPlanes(int begin, int next) {
	// An entry of planes_ for each block of the chunk's pairs that has
	// none; planeBlocks_ lists them (their planes are to be built).
	planeBlocks_.clear();
	for (int p = begin; p < next; ++p) {
		for (const int k : {pairs_[p].first, pairs_[p].second}) {
			if (planeSlot_[k] >= 0) continue;
			if (freePlanes_.empty()) {
				freePlanes_.push_back(static_cast<int>(planes_.size()));
				planes_.emplace_back();
			}
			planeSlot_[k] = freePlanes_.back();
			freePlanes_.pop_back();
			planeBlocks_.push_back(k);
		}
	}
}

void ContactDetection::releasePlanes(int begin, int next, int chunk) {
	// Entries no later chunk needs go back to the free ones.
	for (int p = begin; p < next; ++p) {
		for (const int k : {pairs_[p].first, pairs_[p].second}) {
			if (lastChunk_[k] != chunk || planeSlot_[k] < 0) continue;
			freePlanes_.push_back(planeSlot_[k]);
			planeSlot_[k] = -1;
		}
	}
}

void ContactDetection::detectChunk(Step& step, int begin, int count, int chunk) {
	const std::vector<Block>& blocks = step.blocks;
	StepStatistics& stats = step.stats;
	const int next = begin + count;
	claimPlanes(begin, next);
	const int planeCount = static_cast<int>(planeBlocks_.size());
	int firstContact = 0;
	long friction = 0;
	// The store's contacts are made (default ones, about 800 bytes each: a
	// memory-bound serial pass) for an estimate of the chunk's contacts from
	// the last chunk's contacts per pair, by one thread while the others
	// build planes, and trimmed or grown to the count found when the pairs
	// are done (the pair loop reads nothing of the store's contacts).
	const int estimate = static_cast<int>(std::ceil(kContactEstimateMargin * contactsPerPair_ * count));
	// One team for the chunk: the planes (the barrier after them completes
	// them before any pair reads them), the pairs, the store's intake (one
	// thread: it sets where each pair's contacts go, in pair order, as they
	// would go without chunks) and the contacts' filling and preparation.
#pragma omp parallel if (step.threads)
	{
#pragma omp single nowait
		firstContact = step.store.extend(estimate);
#pragma omp for schedule(dynamic, 32)
		for (int k = 0; k < planeCount; ++k) {
			const Block& block = blocks[planeBlocks_[k]];
			planes_[planeSlot_[planeBlocks_[k]]].compute(*block.shape, block.vertices);
		}
#pragma omp for schedule(dynamic, 16)
		for (int q = 0; q < count; ++q) {
			const auto [a, b] = pairs_[begin + q];
			const Block& A = blocks[a];
			const Block& B = blocks[b];
			pairWork_[q] = NarrowPhaseWork{};
			// Two parts of one concave block never touch (Block::body).
			if ((A.isPart() || B.isPart()) && bodyIndex(blocks, a) == bodyIndex(blocks, b)) {
				pairFound_[q] = 0;
				continue;
			}
			DetectionSettings detection =
			    pairDetectionSettings(diagonals_[a], diagonals_[b], stats.contactDistance, stats.allowedDisplacement);
			detection.keptEdgePoint = step.store.previousEdgePoint(a, b);
			const std::vector<char>* internalA = internalFaces_[a].empty() ? nullptr : &internalFaces_[a];
			const std::vector<char>* internalB = internalFaces_[b].empty() ? nullptr : &internalFaces_[b];
			const std::vector<FaceCover>* coverA = covers_[a].empty() ? nullptr : &covers_[a];
			const std::vector<FaceCover>* coverB = covers_[b].empty() ? nullptr : &covers_[b];
			pairFound_[q] = detectPairContacts(
			    BlockGeometry{A.shape.get(), &A.vertices, interiorPoint(A), internalA, &planes_[planeSlot_[a]], coverA},
			    BlockGeometry{B.shape.get(), &B.vertices, interiorPoint(B), internalB, &planes_[planeSlot_[b]], coverB},
			    detection, pairResults_[q], step.store.previousEntrance(a, b), step.collider.linked(begin + q),
			    &pairWork_[q]);
			// The contact area feeds only the bond strengths (prepareContact: the
			// smaller cohesion and tensile strength of the pair times it): a pair
			// without both leaves it 0 and the forces are the same 0.
			const bool bonded = std::min(A.material.cohesion, B.material.cohesion) > 0 ||
			                    std::min(A.material.tensileStrength, B.material.tensileStrength) > 0;
			if (pairFound_[q]) pairArea_[q] = bonded ? contactArea(pairResults_[q]) : 0.0;
		}
#pragma omp single
		{
			releasePlanes(begin, next, chunk);
			takeChunk(step, begin, count, firstContact);
		}
#pragma omp for schedule(dynamic, 16) reduction(+ : friction)
		for (int q = 0; q < count; ++q) {
			if (!pairFound_[q]) continue;
			const auto [a, b] = pairs_[begin + q];
			friction += storePair(step, a, b, pairResults_[q], pairArea_[q], firstContact + pairFirst_[q]);
		}
	}
	stats.frictionContacts += friction;
}

void ContactDetection::takeChunk(Step& step, int begin, int count, int firstContact) {
	StepStatistics& stats = step.stats;
	int contacts = 0;
	for (int q = 0; q < count; ++q) {
		stats.subUnitTests += pairWork_[q].subUnitTests;
		stats.fullSearchPairs += pairWork_[q].fullSearches;
		if (!pairFound_[q]) continue;
		const auto [a, b] = pairs_[begin + q];
		++stats.contactPairs;
		step.store.setEntrance(a, b, pairResults_[q].entrance);
		pairFirst_[q] = contacts;
		contacts += static_cast<int>(pairResults_[q].contacts.size());
	}
	std::vector<Contact>& all = step.store.contacts();
	const int made = static_cast<int>(all.size()) - firstContact;
	if (contacts < made) all.resize(static_cast<std::size_t>(firstContact + contacts));
	else step.store.extend(contacts - made);
	if (count > 0) contactsPerPair_ = static_cast<double>(contacts) / count;
}

// The pair's contact area [m^2] shared by its sub-contacts (bond strengths):
// the area of the hull of their points on block j, projected along the
// pair's normal, over their number.
double ContactDetection::contactArea(const PairContacts& pair) {
	if (pair.contacts.empty()) return 0.0;
	thread_local std::vector<Vector3> points;
	points.clear();
	for (const SubContact& sub : pair.contacts) points.push_back(sub.pointJ);
	return projectedHullArea(points, pair.normal) / pair.contacts.size();
}

// Each sub-contact takes over its predecessor's history (ContactStore::fill:
// only this pair's previous contacts are candidates, so pairs run on any
// thread) and gets its springs, limits and linearised gap from its own
// blocks alone: the same arithmetic per contact as in any order.
long ContactDetection::storePair(Step& step, int a, int b, const PairContacts& pair, double area, int first) {
	std::vector<Contact>& contacts = step.store.contacts();
	long friction = 0;
	for (std::size_t k = 0; k < pair.contacts.size(); ++k) {
		const SubContact& sub = pair.contacts[k];
		const int i = sub.firstIsA ? a : b, j = sub.firstIsA ? b : a;
		const ContactKey key{i, j, sub.kind, sub.feature1, sub.feature2};
		Contact& contact = contacts[first + k];
		step.store.fill(contact, key, pair.type, sub, *step.blocks[j].shape);
		contact.area = area;
		contact.bodyI = bodyIndex(step.blocks, i);
		contact.bodyJ = bodyIndex(step.blocks, j);
		prepareContact(contact, step.blocks[contact.bodyI], step.blocks[contact.bodyJ], step.settings);
		contact.frictionTangent *= step.frictionScale;
		friction += contact.frictionTangent > 0;
	}
	return friction;
}

std::size_t ContactDetection::memoryBytes() const {
	std::size_t bytes = capacityBytes(pairs_) + capacityBytes(pairResults_) + capacityBytes(pairFound_) +
	                    capacityBytes(pairWork_) + capacityBytes(pairArea_) + capacityBytes(pairFirst_) + capacityBytes(planes_) +
	                    capacityBytes(planeSlot_) + capacityBytes(lastChunk_) + capacityBytes(freePlanes_) +
	                    capacityBytes(planeBlocks_) + capacityBytes(diagonals_);
	// Every pooled result and planes entry, found or not: each keeps its capacity.
	for (const PairContacts& result : pairResults_) bytes += capacityBytes(result.contacts);
	for (const BlockPlanes& planes : planes_) bytes += capacityBytes(planes.faces) + capacityBytes(planes.edges);
	return bytes;
}

void ContactDetection::writeState(StateWriter& out) const {
	out.pod(internalFacesBlocks_);
	out.size(internalFaces_.size());
	for (const auto& faces : internalFaces_) out.podVector(faces);
}

void ContactDetection::readState(StateReader& in) {
	in.pod(internalFacesBlocks_);
	internalFaces_.resize(in.size(8, "internal-face lists"));
	for (auto& faces : internalFaces_) in.podVector(faces, "internal faces");
}

}  // namespace dda
