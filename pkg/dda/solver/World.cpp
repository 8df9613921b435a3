#include "World.hpp"

#include "ContactEquations.hpp"
#include "dda/geometry/MassProperties.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <sstream>

namespace dda {

namespace {
using Clock = std::chrono::steady_clock;
// Per-block loops run in parallel only from this many blocks (or pairs, or
// components) on. Waking an OpenMP team costs tens of microseconds on idle
// cores, and when another process holds a core each barrier can wait a whole
// scheduler slice (milliseconds): a 100-block pile took 44 ms per step with 2
// threads on a loaded 2-core machine, 0.5 ms with one. A block's own work is
// about a microsecond, so below ~1000 blocks threads cannot pay.
constexpr int kMinBlocksForThreads = 1024;
// Candidate pairs per chunk of the narrow phase (detectContacts). It holds the
// results of one chunk's pairs and the planes of about one chunk's blocks, so
// its memory no longer grows with the scene (50,000 slender blocks with MSC:
// 17 MB instead of 81; 10 MB with 4,096). Each chunk is an OpenMP team with a
// barrier inside, and on a loaded machine each can wait a scheduler slice:
// with 2 threads on a loaded 2-core machine, 10,000 slender blocks under DESS
// (64,000 pairs) had a narrow phase up to twice as long with chunks of 2,048,
// 1.5 times with 4,096, and with 8,192 no longer than without chunks.
constexpr int kPairChunk = 8192;
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
// A pass of the iteration has converged when, besides no state changing,
// every contact's tangential force agrees with the model the last solve used
// (a slipping contact's direction is linearised) to within this fraction of
// the largest normal force of its group. Newton's method converges
// quadratically there, so a tight tolerance costs about one solve more; at
// 1e-4 the forces left over pushed a cube sliding along x sideways by 1e-7
// m in a set-up symmetric in y.
constexpr double kNewtonTolerance = 1e-10;
// A step's friction limits are consistent with its normal forces when a pass
// changes none by more than this fraction of the largest; a step makes at
// most kLimitPasses passes (see step()). Any limit >= 0 resists slip, so an
// unsettled limit is an error in the friction's size, not in the energy.
constexpr double kLimitTolerance = 1e-3;
constexpr int kLimitPasses = 12;
// Solves of a step's iteration that take Newton's full step before the line
// search is used regardless (see step()).
constexpr int kFullNewtonSolves = 4;
// Start from rest (World::settle): friction tangents are multiplied by this
// while settling (the contacts' tangential springs hold whatever the
// equilibrium asks), the static steps stop once one moves the blocks by no
// more than kSettleTolerance of what the first did, and give up after
// kSettleSteps (each closes all but about 1e-3 of the way, see settle).
constexpr double kSettleFrictionScale = 1e6;
constexpr double kSettleTolerance = 1e-6;
constexpr int kSettleSteps = 12;
// Heap for the contact terms kept within an attempt (World::keptTerms_):
// about 3,400 contacts; the others' terms are made at every solve.
constexpr std::size_t kKeptTermsBytes = std::size_t(16) << 20;
double secondsSince(Clock::time_point start) {
	return std::chrono::duration<double>(Clock::now() - start).count();
}
// CPU time of the whole process, all threads [s] (not wall time: a busy or
// virtualised machine's waits are not counted).
double processCpuSeconds() {
	timespec now{};
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
	return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}
void requireFinite(const Vector3& v, const char* what) {
	if (!v.allFinite()) {
		std::ostringstream message;
		message << what << " must be finite, got (" << v.x() << ", " << v.y() << ", " << v.z() << ")";
		throw InputError(message.str());
	}
}
// Corner x lies in the convex polygon `face` of `vertices` (normal n,
// counter-clockwise seen from outside), within `tolerance` [m].
bool insidePolygon(const Vector3& x, const std::vector<Vector3>& vertices, const std::vector<int>& face,
                   const Vector3& n, double tolerance) {
	for (std::size_t k = 0; k < face.size(); ++k) {
		const Vector3& p = vertices[face[k]];
		const Vector3& q = vertices[face[(k + 1) % face.size()]];
		const Vector3 inward = n.cross(q - p);
		const double length = inward.norm();
		if (length > 0 && (x - p).dot(inward) < -tolerance * length) return false;
	}
	return true;
}

// Marks, for every fixed block, the faces fully covered by a coplanar,
// opposed face of another fixed block (flush joints): see
// BlockGeometry::internalFaces. Fixed blocks never move, so this runs only
// when blocks are added. Pairs are found by sorting boxes along x.
void markInternalFaces(const std::vector<Block>& blocks, std::vector<std::vector<char>>& internal) {
	internal.assign(blocks.size(), {});
	std::vector<int> fixed;
	std::vector<Eigen::AlignedBox3d> boxes(blocks.size());
	for (std::size_t b = 0; b < blocks.size(); ++b) {
		if (!blocks[b].fixed) continue;
		fixed.push_back(static_cast<int>(b));
		internal[b].assign(blocks[b].shape->faces.size(), 0);
		for (const Vector3& x : blocks[b].vertices) boxes[b].extend(x);
	}
	std::sort(fixed.begin(), fixed.end(), [&](int a, int b) { return boxes[a].min().x() < boxes[b].min().x(); });
	for (std::size_t i = 0; i < fixed.size(); ++i) {
		const int a = fixed[i];
		for (std::size_t j = i + 1; j < fixed.size(); ++j) {
			const int b = fixed[j];
			const double tolerance =
			    kDefaultRelativeLengthTolerance * std::max(boxes[a].diagonal().norm(), boxes[b].diagonal().norm());
			if (boxes[b].min().x() > boxes[a].max().x() + tolerance) break;
			Eigen::AlignedBox3d grown = boxes[a];
			grown.min().array() -= tolerance;
			grown.max().array() += tolerance;
			if (!grown.intersects(boxes[b])) continue;
			const Block& A = blocks[a];
			const Block& B = blocks[b];
			for (std::size_t f = 0; f < A.shape->faces.size(); ++f) {
				const Vector3 nf = faceNormal(A.vertices, A.shape->faces[f]);
				const Vector3& pf = A.vertices[A.shape->faces[f][0]];
				for (std::size_t g = 0; g < B.shape->faces.size(); ++g) {
					const Vector3 ng = faceNormal(B.vertices, B.shape->faces[g]);
					if (nf.dot(ng) > -1 + kDefaultParallelAngleTolerance * kDefaultParallelAngleTolerance) continue;
					bool coplanar = true;
					for (int v : B.shape->faces[g]) coplanar = coplanar && std::abs(nf.dot(B.vertices[v] - pf)) <= tolerance;
					if (!coplanar) continue;
					bool fCovered = true, gCovered = true;
					for (int v : A.shape->faces[f])
						fCovered = fCovered && insidePolygon(A.vertices[v], B.vertices, B.shape->faces[g], ng, tolerance);
					for (int v : B.shape->faces[g])
						gCovered = gCovered && insidePolygon(B.vertices[v], A.vertices, A.shape->faces[f], nf, tolerance);
					if (fCovered) internal[a][f] = 1;
					if (gCovered) internal[b][g] = 1;
				}
			}
		}
	}
}

// Area [m^2] of the convex hull of the points projected on the plane
// perpendicular to `normal` (Andrew's monotone chain, then the shoelace
// formula); 0 for fewer than 3 points or collinear ones.
double projectedHullArea(const std::vector<Vector3>& points, const Vector3& normal) {
	if (points.size() < 3) return 0;
	const Vector3 u = normal.unitOrthogonal(), v = normal.normalized().cross(u);
	std::vector<std::pair<double, double>> p;
	p.reserve(points.size());
	for (const Vector3& x : points) p.emplace_back(u.dot(x - points[0]), v.dot(x - points[0]));
	std::sort(p.begin(), p.end());
	auto cross = [](const std::pair<double, double>& o, const std::pair<double, double>& a,
	                const std::pair<double, double>& b) {
		return (a.first - o.first) * (b.second - o.second) - (a.second - o.second) * (b.first - o.first);
	};
	std::vector<std::pair<double, double>> hull(2 * p.size());
	std::size_t k = 0;
	for (std::size_t i = 0; i < p.size(); ++i) {
		while (k >= 2 && cross(hull[k - 2], hull[k - 1], p[i]) <= 0) --k;
		hull[k++] = p[i];
	}
	for (std::size_t i = p.size() - 1, lower = k + 1; i-- > 0;) {
		while (k >= lower && cross(hull[k - 2], hull[k - 1], p[i]) <= 0) --k;
		hull[k++] = p[i];
	}
	double twice = 0;
	for (std::size_t i = 0; i + 1 < k; ++i) twice += hull[i].first * hull[i + 1].second - hull[i + 1].first * hull[i].second;
	return 0.5 * std::abs(twice);
}
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

int World::addBlock(const std::vector<Vector3>& points, const Material& material, bool fixed, bool rigid) {
	Block block = makeBlock(points, material, fixed, rigid);
	block.shape = topologies_.intern(std::move(block.shape));
	blocks_.push_back(std::move(block));
	return blockCount() - 1;
}

void World::reserveBlocks(int extra) {
	const std::size_t needed = blocks_.size() + static_cast<std::size_t>(std::max(extra, 0));
	if (needed > blocks_.capacity()) blocks_.reserve(std::max(needed, 2 * blocks_.size()));
}

Block makeBlock(const std::vector<Vector3>& points, const Material& material, bool fixed, bool rigid) {
	validateMaterial(material);
	ConvexPolyhedron polyhedron = buildConvexPolyhedron(points);
	const MassProperties properties = computeMassProperties(polyhedron.vertices, polyhedron.faces);
	Block block;
	block.vertices = polyhedron.vertices;
	block.initialVertices = std::move(polyhedron.vertices);
	block.shape = std::make_shared<const PolyhedronTopology>(std::move(static_cast<PolyhedronTopology&>(polyhedron)));
	block.centroid = properties.centroid;
	block.volume = properties.volume;
	block.secondMoment = properties.secondMoment;
	block.mass = material.density * properties.volume;
	block.size = std::cbrt(properties.volume);
	block.material = material;
	block.fixed = fixed;
	block.rigid = rigid;
	return block;
}

Block& World::block(int index) {
	if (index < 0 || index >= blockCount()) {
		std::ostringstream message;
		message << "no DDA block with index " << index << " (the scene has " << blockCount() << ")";
		throw std::out_of_range(message.str());
	}
	return blocks_[index];
}
const Block& World::block(int index) const { return const_cast<World*>(this)->block(index); }

void World::addFixedPoint(int index, const Vector3& position, double stiffness) {
	requireFinite(position, "a fixed point");
	if (!std::isfinite(stiffness)) throw InputError("fixed point stiffness must be finite");
	Block& b = block(index);
	if (b.fixed) throw InputError("block " + std::to_string(index) + " is fixed: a fixed point would have no effect");
	b.fixedPoints.push_back({position, position, stiffness});
}

void World::addPointLoad(int index, const Vector3& position, const Vector3& force) {
	requireFinite(position, "a point load's position");
	requireFinite(force, "a point load's force");
	Block& b = block(index);
	if (b.fixed) throw InputError("block " + std::to_string(index) + " is fixed: a point load would have no effect");
	b.loads.push_back({position, force});
}

void World::setVelocity(int index, const Vector3& velocity, const Vector3& angularVelocity) {
	requireFinite(velocity, "velocity");
	requireFinite(angularVelocity, "angular velocity");
	Block& b = block(index);
	if (b.fixed && !(velocity.isZero() && angularVelocity.isZero()))
		throw InputError("a fixed block cannot be given a velocity");
	b.velocity.head<3>() = velocity;
	b.velocity.segment<3>(3) = angularVelocity;
}

void World::setStress(int index, const Vector6& stress) {
	if (!stress.allFinite()) throw InputError("initial stress must be finite");
	Block& b = block(index);
	if (b.rigid && !stress.isZero()) {
		std::ostringstream message;
		message << "block " << index << " is rigid: it has no strain and carries no stress, so it cannot be given an "
		        << "initial stress (got (" << stress.transpose() << ") Pa)";
		throw InputError(message.str());
	}
	b.stress = stress;
}

double World::sceneHalfSize() {
	if (sceneSizedBlocks_ != blockCount()) {
		Eigen::AlignedBox3d box;
		for (const Block& b : blocks_)
			for (const Vector3& x : b.vertices) box.extend(x);
		sceneHalfSize_ = box.isEmpty() ? 0.0 : 0.5 * box.sizes().maxCoeff();
		sceneSizedBlocks_ = blockCount();
	}
	return sceneHalfSize_;
}

void World::setCollider(std::unique_ptr<Collider> collider) {
	if (!collider) throw InputError("a collider is required");
	collider_ = std::move(collider);
}

const Vector12& World::solutionOf(int block) const {
	static const Vector12 zero = Vector12::Zero();
	const int k = movingIndex_[block];
	return k < 0 ? zero : iterate_[k];
}

Vector12 World::startVelocityOf(int block, const IntegratorSettings& settings) const {
	if (movingIndex_[block] < 0) return Vector12::Zero();
	return startVelocity(blocks_[block], settings);
}

void World::detectContacts(const IntegratorSettings& settings, StepStatistics& stats) {
	auto phase = Clock::now();
	double cpu = processCpuSeconds();
	BroadPhaseStatistics broad;
	collider_->setPairReuse(settings.reuseCandidatePairs);
	collider_->findPairs(blocks_, stats.contactDistance, pairs_, broad);
	stats.candidatePairs = broad.candidatePairs;
	stats.shellPairs = broad.shellPairs;
	stats.shellTests = broad.shellTests;
	stats.shells = broad.shells;
	stats.shellUpdates = broad.shellUpdates;
	stats.subUnitPairs = broad.subUnitPairs;
	stats.broadPhaseSkipped = broad.broadPhaseSkipped;
	stats.pairsReused = broad.pairsReused;
	stats.blocksResearched = broad.blocksResearched;
	for (const auto& [a, b] : pairs_) stats.fixedPairsSearched += blocks_[a].fixed && blocks_[b].fixed;
	stats.timeBroadPhase = secondsSince(phase);
	stats.cpuBroadPhase = processCpuSeconds() - cpu;

	phase = Clock::now();
	cpu = processCpuSeconds();
	store_.beginStep();  // the contact store's work, timed with the narrow phase
	if (internalFacesBlocks_ != blockCount()) {
		markInternalFaces(blocks_, internalFaces_);
		internalFacesBlocks_ = blockCount();
	}
	const int pairCount = static_cast<int>(pairs_.size());
	// Threads by the step's pair count, not the chunk's: a small scene stays
	// serial, and a large one's chunks (all but perhaps its last) are large.
	const bool threads = pairCount >= kMinBlocksForThreads;
	std::vector<double>& diagonal = diagonals_;
	diagonal.resize(blocks_.size());
	for (std::size_t b = 0; b < blocks_.size(); ++b) diagonal[b] = boundingDiagonal(blocks_[b]);
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
	lastChunk_.resize(blocks_.size());
	for (int p = 0; p < pairCount; ++p) lastChunk_[pairs_[p].first] = lastChunk_[pairs_[p].second] = p / kPairChunk;
	planeSlot_.assign(blocks_.size(), -1);
	freePlanes_.clear();
	for (int k = static_cast<int>(planes_.size()) - 1; k >= 0; --k) freePlanes_.push_back(k);
	const int chunkCapacity = std::min(pairCount, kPairChunk);
	if (static_cast<int>(pairResults_.size()) < chunkCapacity) pairResults_.resize(chunkCapacity);
	pairFound_.resize(chunkCapacity);
	pairWork_.resize(chunkCapacity);
	for (int begin = 0, chunk = 0; begin < pairCount; begin += kPairChunk, ++chunk) {
		const int count = std::min(kPairChunk, pairCount - begin);
		const int next = begin + count;
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
		const int planeCount = static_cast<int>(planeBlocks_.size());
		// One team for both loops: the barrier after the first completes the
		// planes before any pair reads them, the region's end waits for the
		// pairs (nowait: no barrier of its own).
#pragma omp parallel if (threads)
		{
#pragma omp for schedule(dynamic, 32)
			for (int k = 0; k < planeCount; ++k) {
				const Block& block = blocks_[planeBlocks_[k]];
				planes_[planeSlot_[planeBlocks_[k]]].compute(*block.shape, block.vertices);
			}
#pragma omp for schedule(dynamic, 16) nowait
			for (int q = 0; q < count; ++q) {
				const auto [a, b] = pairs_[begin + q];
				const Block& A = blocks_[a];
				const Block& B = blocks_[b];
				const DetectionSettings detection =
				    pairDetectionSettings(diagonal[a], diagonal[b], stats.contactDistance, stats.allowedDisplacement);
				const std::vector<char>* internalA = internalFaces_[a].empty() ? nullptr : &internalFaces_[a];
				const std::vector<char>* internalB = internalFaces_[b].empty() ? nullptr : &internalFaces_[b];
				pairWork_[q] = NarrowPhaseWork{};
				pairFound_[q] = detectPairContacts(
				    BlockGeometry{A.shape.get(), &A.vertices, A.centroid, internalA, &planes_[planeSlot_[a]]},
				    BlockGeometry{B.shape.get(), &B.vertices, B.centroid, internalB, &planes_[planeSlot_[b]]},
				    detection, pairResults_[q], store_.previousEntrance(a, b), collider_->linked(begin + q),
				    &pairWork_[q]);
			}
		}
		// Entries no later chunk needs go back to the free ones.
		for (int p = begin; p < next; ++p) {
			for (const int k : {pairs_[p].first, pairs_[p].second}) {
				if (lastChunk_[k] != chunk || planeSlot_[k] < 0) continue;
				freePlanes_.push_back(planeSlot_[k]);
				planeSlot_[k] = -1;
			}
		}
		// The chunk's results into the store in pair order, as they would be
		// without chunks: the pair loop reads only the previous step's
		// entrances from the store, which these calls leave alone.
		for (int q = 0; q < count; ++q) {
			stats.subUnitTests += pairWork_[q].subUnitTests;
			stats.fullSearchPairs += pairWork_[q].fullSearches;
			if (!pairFound_[q]) continue;
			const auto [a, b] = pairs_[begin + q];
			const PairContacts& pair = pairResults_[q];
			++stats.contactPairs;
			store_.setEntrance(a, b, pair.entrance);
			// The pair's contact area, shared by its sub-contacts (bond strengths).
			points_.clear();
			for (const SubContact& sub : pair.contacts) points_.push_back(sub.pointJ);
			const double area =
			    pair.contacts.empty() ? 0.0 : projectedHullArea(points_, pair.normal) / pair.contacts.size();
			for (const SubContact& sub : pair.contacts) {
				const int i = sub.firstIsA ? a : b, j = sub.firstIsA ? b : a;
				const ContactKey key{i, j, sub.kind, sub.feature1, sub.feature2};
				Contact& contact = store_.add(key, pair.type, sub, *blocks_[i].shape, *blocks_[j].shape);
				contact.area = area;
				prepareContact(contact, blocks_[i], blocks_[j], settings);
				contact.frictionTangent *= frictionScale_;
				stats.frictionContacts += contact.frictionTangent > 0;
			}
		}
	}
	stats.contacts = static_cast<int>(store_.contacts().size());
	stats.timeNarrowPhase = secondsSince(phase);
	stats.cpuNarrowPhase = processCpuSeconds() - cpu;
}

World::MemoryUse World::memoryUse() const {
	MemoryUse use;
	use.collider = collider_->memoryBytes();
	use.contacts = store_.memoryBytes();
	use.narrowPhase = capacityBytes(pairs_) + capacityBytes(pairResults_) + capacityBytes(pairFound_) +
	                  capacityBytes(pairWork_) + capacityBytes(points_) + capacityBytes(planes_) +
	                  capacityBytes(planeSlot_) + capacityBytes(lastChunk_) + capacityBytes(freePlanes_) +
	                  capacityBytes(planeBlocks_) + capacityBytes(diagonals_);
	// Every pooled result and planes entry, found or not: each keeps its capacity.
	for (const PairContacts& result : pairResults_) use.narrowPhase += capacityBytes(result.contacts);
	for (const BlockPlanes& planes : planes_) use.narrowPhase += capacityBytes(planes.faces) + capacityBytes(planes.edges);
	use.solver = coupled_.memoryBytes() + capacityBytes(moving_) + capacityBytes(movingIndex_) +
	             capacityBytes(solutions_) + capacityBytes(motions_) + capacityBytes(ownSystems_) +
	             capacityBytes(ownSystemOf_) + capacityBytes(solvedAlone_) + capacityBytes(links_) +
	             capacityBytes(hasSprings_) + capacityBytes(blockUnknowns_) + capacityBytes(iterate_) +
	             capacityBytes(deltas_) + capacityBytes(lines_) + capacityBytes(groupRoot_) + capacityBytes(lineGroup_) +
	             capacityBytes(groupLines_) + capacityBytes(orderedLines_) + capacityBytes(keptTerms_) +
	             capacityBytes(keptTermsOf_) + capacityBytes(keptTermsKey_) + capacityBytes(groupKink_) +
	             capacityBytes(groupSlope_) + capacityBytes(groupCurvature_) + capacityBytes(groupStep_) +
	             capacityBytes(contactGroup_) + capacityBytes(startAccelerations_) + group_.memoryBytes();
	return use;
}

void World::buildSystemStructure(int movingBlocks, StepStatistics& stats) {
	links_.clear();
	hasSprings_.assign(movingBlocks, 0);
	for (int k = 0; k < movingBlocks; ++k) hasSprings_[k] = !blocks_[moving_[k]].fixedPoints.empty();
	for (const Contact& contact : store_.contacts()) {
		// No terms (open, and no tangential spring): couples nothing.
		if (!hasNormalTerms(contact) && tangentialTerm(contact) == TangentialTerm::None) continue;
		const int mi = movingIndex_[contact.key.blockI], mj = movingIndex_[contact.key.blockJ];
		if (mi >= 0) hasSprings_[mi] = 1;
		if (mj >= 0) hasSprings_[mj] = 1;
		if (mi >= 0 && mj >= 0) links_.emplace_back(mi, mj);
	}
	coupled_.build(movingBlocks, links_, hasSprings_, blockUnknowns_);
	aloneUnknowns_ = 0;
	for (int k = 0; k < movingBlocks; ++k)
		if (!hasSprings_[k]) aloneUnknowns_ += blockUnknowns_[k];
	++stats.systemStructures;
	// A block left alone is a component of its own.
	const int alone = movingBlocks - coupled_.blocks();
	stats.components = coupled_.components() + alone;
	stats.largestComponent = std::max(coupled_.largestComponent(), alone > 0 ? 1 : 0);
}

void World::assembleOwnSystems(const IntegratorSettings& settings, double dt) {
	const int n = static_cast<int>(moving_.size());
	const int kept = static_cast<int>(ownSystems_.size());
	int count = kept;
	for (int k = 0; k < n; ++k)
		if (coupled_.coupled(k) && ownSystemOf_[k] < 0) ownSystemOf_[k] = count++;
	ownSystems_.resize(count);
#pragma omp parallel for schedule(static) if (count - kept >= kMinBlocksForThreads)
	for (int k = 0; k < n; ++k)
		if (ownSystemOf_[k] >= kept)
			assembleBlock(blocks_[moving_[k]], settings, dt, startAccelerationOf(k), ownSystems_[ownSystemOf_[k]]);
}

void World::solveAloneBlocks(const IntegratorSettings& settings, double dt) {
	const int n = static_cast<int>(moving_.size());
	int unsolved = 0;
	for (int k = 0; k < n; ++k) {
		if (coupled_.coupled(k))
			solvedAlone_[k] = 0;  // coupled_.solve writes its solution
		else
			unsolved += !solvedAlone_[k];
	}
	// Threads only for work: each parallel region can wait a scheduler slice
	// on a loaded machine (kMinBlocksForThreads).
#pragma omp parallel for schedule(static) if (unsolved >= kMinBlocksForThreads)
	for (int k = 0; k < n; ++k) {
		if (coupled_.coupled(k) || solvedAlone_[k]) continue;
		const Block& block = blocks_[moving_[k]];
		BlockSystem system;
		assembleBlock(block, settings, dt, startAccelerationOf(k), system);
		solutions_[k] = solveBlock(block, system);
		solvedAlone_[k] = 1;
	}
}

void World::assembleContacts(StepStatistics& stats) {
	Matrix24 stiffnessWork;
	Vector24 forceWork;
	const std::vector<Contact>& contacts = store_.contacts();
	keptTermsOf_.resize(contacts.size(), -1);
	keptTermsKey_.resize(contacts.size(), 0);
	for (std::size_t c = 0; c < contacts.size(); ++c) {
		const Contact& contact = contacts[c];
		const int bi = contact.key.blockI, bj = contact.key.blockJ;
		const bool normalTerms = hasNormalTerms(contact);
		const TangentialTerm tangential = tangentialTerm(contact);
		// No terms (what contactTerms returns false for).
		if (!normalTerms && tangential == TangentialTerm::None) continue;
		// Kept terms while the state is the one they were made for (see
		// keptTerms_ in World.hpp): not a slipping contact's, which depend
		// on its stretch, nor a secant's (gamma < 1), which depend on its
		// trial gap; both are made anew at every solve.
		const bool keepable =
		    tangential != TangentialTerm::FrictionLoad && !(normalTerms && contact.secantWeight > 0);
		const unsigned char key = static_cast<unsigned char>(1 + normalTerms + 2 * static_cast<int>(tangential));
		const Matrix24* stiffnessOf = &stiffnessWork;
		const Vector24* forceOf = &forceWork;
		const int kept = keptTermsOf_[c];
		if (keepable && kept >= 0 && keptTermsKey_[c] == key) {
			stiffnessOf = &keptTerms_[kept].stiffness;
			forceOf = &keptTerms_[kept].force;
		} else {
			contactTerms(contact, blocks_[bi], blocks_[bj], stiffnessWork, forceWork);
			if (keepTerms_ && keepable &&
			    (kept >= 0 || (keptTerms_.size() + 1) * sizeof(KeptTerms) <= kKeptTermsBytes)) {
				if (kept < 0) {
					// Grown by hand so that its capacity stays within the budget.
					if (keptTerms_.size() == keptTerms_.capacity())
						keptTerms_.reserve(std::min(std::max<std::size_t>(64, 2 * keptTerms_.capacity()),
						                            kKeptTermsBytes / sizeof(KeptTerms)));
					keptTermsOf_[c] = static_cast<int>(keptTerms_.size());
					keptTerms_.emplace_back();
				}
				KeptTerms& entry = keptTerms_[keptTermsOf_[c]];
				entry.stiffness = stiffnessWork;
				entry.force = forceWork;
				keptTermsKey_[c] = key;
			}
		}
		const Matrix24& stiffness = *stiffnessOf;
		const Vector24& force = *forceOf;
		// An open contact may carry its tangential spring alone (its limit is
		// held for the pass): only closed ones have a normal spring.
		stats.normalTerms += normalTerms;
		stats.frictionTerms += tangential != TangentialTerm::None;
		const int mi = movingIndex_[bi], mj = movingIndex_[bj];
		if (mi >= 0) {
			coupled_.diagonal(mi) += stiffness.topLeftCorner<12, 12>();
			coupled_.force(mi) += force.head<12>();
		}
		if (mj >= 0) {
			coupled_.diagonal(mj) += stiffness.bottomRightCorner<12, 12>();
			coupled_.force(mj) += force.tail<12>();
		}
		if (mi >= 0 && mj >= 0) {
			bool transposed;
			Matrix12& offDiagonal = coupled_.offDiagonal(mi, mj, transposed);
			offDiagonal += transposed ? stiffness.bottomLeftCorner<12, 12>() : stiffness.topRightCorner<12, 12>();
		}
	}
}

void World::groupContacts() {
	const int n = static_cast<int>(moving_.size());
	std::vector<int>& root = groupRoot_;
	root.resize(n);
	for (int k = 0; k < n; ++k) root[k] = k;
	auto find = [&](int k) {
		while (root[k] != k) k = root[k] = root[root[k]];
		return k;
	};
	const std::vector<Contact>& contacts = store_.contacts();
	for (const Contact& contact : contacts) {
		const int mi = movingIndex_[contact.key.blockI], mj = movingIndex_[contact.key.blockJ];
		if (mi < 0 || mj < 0) continue;
		const int a = find(mi), b = find(mj);
		if (a != b) root[std::max(a, b)] = std::min(a, b);
	}
	for (int k = 0; k < n; ++k) root[k] = find(k);
	contactGroup_.resize(contacts.size());
	for (std::size_t c = 0; c < contacts.size(); ++c) {
		const int mi = movingIndex_[contacts[c].key.blockI];
		contactGroup_[c] = root[mi >= 0 ? mi : movingIndex_[contacts[c].key.blockJ]];
	}
}

void World::GroupIteration::reset(int groups) {
	done.assign(groups, 0);
	hasContacts.assign(groups, 0);
	swungBack.assign(groups, 0);
	passes.assign(groups, 0);
	passSolves.assign(groups, 0);
	changes.assign(groups, 0);
	newPass.assign(groups, 0);
	forceChange.assign(groups, 0.0);
	largestNormalForce.assign(groups, 0.0);
	limitChange.assign(groups, 0.0);
	largestLimit.assign(groups, 0.0);
}

void World::GroupIteration::startIteration() {
	for (std::size_t g = 0; g < done.size(); ++g) {
		if (done[g]) continue;
		++passSolves[g];
		changes[g] = 0;
		newPass[g] = 0;
		forceChange[g] = largestNormalForce[g] = limitChange[g] = largestLimit[g] = 0;
	}
}

std::size_t World::GroupIteration::memoryBytes() const {
	return capacityBytes(done) + capacityBytes(hasContacts) + capacityBytes(swungBack) + capacityBytes(newPass) +
	       capacityBytes(passes) + capacityBytes(passSolves) + capacityBytes(changes) + capacityBytes(forceChange) +
	       capacityBytes(largestNormalForce) + capacityBytes(limitChange) + capacityBytes(largestLimit);
}

bool World::GroupIteration::passConverged(int g, double tolerance) const {
	return changes[g] == 0 && forceChange[g] <= tolerance * largestNormalForce[g];
}

double World::lineSearch(const IntegratorSettings& settings, double dt) {
	const int n = static_cast<int>(moving_.size());
	deltas_.resize(n);
	for (int k = 0; k < n; ++k) deltas_[k] = solutions_[k] - iterate_[k];
	auto deltaOf = [&](int block) -> const Vector12& {
		static const Vector12 zero = Vector12::Zero();
		const int k = movingIndex_[block];
		return k < 0 ? zero : deltas_[k];
	};
	const std::vector<int>& root = groupRoot_;
	std::vector<Contact>& contacts = store_.contacts();
	// Per group (by its root): whether its true energy must be searched,
	// its blocks' slope and curvature along the step, its contacts' lines.
	// The Newton step is the exact minimiser of the model along the line
	// unless some contact crosses a kink of its energy on the way (a gap
	// changing sign against its state, a stuck stretch passing its limit,
	// when `searchKinks`) or slips.
	groupKink_.assign(n, 0);
	groupSlope_.assign(n, 0.0);
	groupCurvature_.assign(n, 0.0);
	lines_.clear();
	lineGroup_.clear();
	for (std::size_t c = 0; c < contacts.size(); ++c) {
		const Contact& contact = contacts[c];
		const int bi = contact.key.blockI, bj = contact.key.blockJ;
		const int group = contactGroup_[c];
		// A slipping contact's force is not quadratic, so a group with one is
		// always searched. Opening and closing are searched once a contact of
		// the group has swung back (opened and closed again, or the reverse)
		// or its pass runs long: a searched step stops at the energy's minimum
		// along the way, often where the first of many impacting corners
		// touches, so searching those from the start cost a stiff pile one
		// solve per closing contact.
		const bool searchKinks = group_.swungBack[group] || group_.passSolves[group] >= kFullNewtonSolves;
		const ContactLine line = contactLine(contact, blocks_[bi], blocks_[bj], solutionOf(bi), solutionOf(bj),
		                                     deltaOf(bi), deltaOf(bj));
		lines_.push_back(line);
		lineGroup_.push_back(group);
		bool kink = false;
		if (contact.normal.valid && searchKinks) {
			const double g0 = line.gap, g1 = line.gap + line.gapRate;
			kink = isClosed(contact) ? (!line.bonded && std::max(g0, g1) > 0) : std::min(g0, g1) < 0;
			// The secant force is quadratic in energy only where the contact
			// is closed at both ends of the step.
			if (contact.secantWeight > 0 && !line.bonded)
				kink = kink || (line.startGap < 0 ? std::max(g0, g1) > 0 : std::min(g0, g1) < 0);
		}
		if (searchKinks && !contact.slipping && line.tangential)
			kink = kink || (line.stretch + line.stretchRate).norm() > line.limit / line.shearStiffness;
		// A slipping contact's force is not quadratic: its model is exact
		// only at the iterate, and Newton's steps alone can swing about the
		// minimum (seen: the same tangential forces every other solve).
		kink = kink || (contact.slipping && line.tangential);
		if (kink) groupKink_[group] = 1;
	}
	// d Phi / dt along D_k + t Delta: the blocks' quadratic energy
	// 1/2 D^T K D - f^T D, plus each contact's (ContactLine). Phi is convex,
	// so the derivative rises with t; it is negative at 0 (the Newton step
	// descends), and the minimiser is where it vanishes.
	BlockSystem own;
	for (int k = 0; k < n; ++k) {
		if (!groupKink_[root[k]] || deltas_[k].isZero()) continue;
		const BlockSystem* system = &own;
		if (ownSystemOf_[k] >= 0)
			system = &ownSystems_[ownSystemOf_[k]];
		else
			assembleBlock(blocks_[moving_[k]], settings, dt, startAccelerationOf(k), own);
		groupSlope_[root[k]] += deltas_[k].dot(system->stiffness * iterate_[k] - system->force);
		groupCurvature_[root[k]] += deltas_[k].dot(system->stiffness * deltas_[k]);
	}
	// The lines of each searched group, together (a counting sort by group).
	groupStep_.assign(n, 1.0);
	groupLines_.assign(n + 1, 0);
	for (std::size_t c = 0; c < lines_.size(); ++c)
		if (groupKink_[lineGroup_[c]]) ++groupLines_[lineGroup_[c] + 1];
	for (int g = 0; g < n; ++g) groupLines_[g + 1] += groupLines_[g];
	// Copied in that order, so the bisection reads each group's lines
	// contiguously (and sums them in the same order as before).
	orderedLines_.resize(groupLines_[n]);
	{
		std::vector<int> next(groupLines_.begin(), groupLines_.end() - 1);
		for (std::size_t c = 0; c < lines_.size(); ++c)
			if (groupKink_[lineGroup_[c]]) orderedLines_[next[lineGroup_[c]]++] = lines_[c];
	}
	double smallest = 1;
	for (int g = 0; g < n; ++g) {
		if (!groupKink_[g] || group_.done[g]) continue;
		// Bisection on the derivative (searchLine; certified: the same
		// result with fewer evaluations).
		const double t = searchLine(orderedLines_.data() + groupLines_[g], orderedLines_.data() + groupLines_[g + 1],
		                            groupSlope_[g], groupCurvature_[g], keepTerms_);
		// A step this close to the full one lowers the energy by no
		// measurable amount more: take the Newton point.
		if (t <= 1 - 1e-9) groupStep_[g] = t;
		smallest = std::min(smallest, groupStep_[g]);
	}
	for (int k = 0; k < n; ++k) {
		if (group_.done[root[k]]) continue;  // converged: kept
		const double t = groupStep_[root[k]];
		if (t == 1)
			iterate_[k] = solutions_[k];
		else
			iterate_[k] += t * deltas_[k];
	}
	return smallest;
}

const Vector12& World::startAccelerationOf(int k) const {
	static const Vector12 zero = Vector12::Zero();
	return startAccelerations_.empty() ? zero : startAccelerations_[k];
}

void World::computeStartAccelerations(const IntegratorSettings& settings) {
	const int n = static_cast<int>(moving_.size());
	startAccelerations_.clear();
	if (settings.shiScheme()) return;
	startAccelerations_.resize(n);
	for (int k = 0; k < n; ++k) {
		const Block& block = blocks_[moving_[k]];
		startAccelerations_[k] = accelerationOf(block, restForce(block, settings));
	}
}

EnergyAccount World::energy() const {
	EnergyAccount account = energy_;
	account.kinetic = account.gravity = account.strain = 0;
	for (const Block& block : blocks_) {
		if (block.fixed) continue;
		account.gravity -= block.mass * gravity_.dot(block.centroid);
		account.kinetic += kineticEnergy(block, block.velocity);
		if (!block.rigid && !block.stress.isZero())
			// W = V0/2 tau^T E^-1 tau, tau = (V / V0) sigma (BlockEquations.hpp).
			account.strain += 0.5 * (block.volume * block.volume / block.referenceVolume()) *
			                  block.stress.dot(block.elasticity().ldlt().solve(block.stress));
	}
	return account;
}

void World::accountStep(const IntegratorSettings& settings) {
	// Blocks. Shi's scheme (v1 = 2D/dt - v0, (2/dt^2) M D = (2/dt) M v0 + F(D))
	// gives 1/2 v1^T M v1 - 1/2 v0^T M v0 = F(D) . D exactly: the kinetic
	// energy changes by the work of the end-of-step forces over D. Gravity's
	// work is minus the change of its potential exactly (the centroid moves
	// by D's translation). The elastic force -V0 (tau0 + E eps) has the
	// potential V0 (tau0 . eps + eps^T E eps / 2) (the change of the strain
	// energy, at any strain: BlockEquations.hpp, "Finite strain") and the
	// Bregman divergence V0/2 eps^T E eps: the damping. Point
	// loads and fixed-point springs (end-of-step force) do the work F . u.
	// Every member of Newmark's family with beta = gamma/2 moves the blocks
	// by the trapezoidal rule, D = dt (v0 + v1)/2, so exactly
	//   dKE = ((1 - gamma) F_s(0) + gamma F_s(D)) . D + G . D,
	// F_s the blocks' own forces (a0 = M^-1 F_s(0)) and G the contacts'
	// mean force (ContactEquations.hpp). F_s is affine in D: the elastic
	// force's work is minus the change of the strain energy minus (2 gamma
	// - 1) times its Bregman divergence (the damping; 0 for average
	// acceleration), a fixed point's F(0) (1 - gamma) + F(D) gamma.
	const double gamma = settings.newmarkGamma;
	const int n = static_cast<int>(moving_.size());
	for (int k = 0; k < n; ++k) {
		const Block& block = blocks_[moving_[k]];
		const Vector12& D = solutions_[k];
		if (settings.velocityRatio < 1) {
			// Velocities scaled by velocityRatio at the step's start: the
			// kinetic energy removed is damping.
			const double ratio = settings.velocityRatio;
			energy_.damping += (1 - ratio * ratio) * kineticEnergy(block, block.velocity);
		}
		if (!block.rigid) {
			const Vector6 strain = D.segment<6>(6);
			energy_.damping += (2 * gamma - 1) * 0.5 * block.referenceVolume() * strain.dot(block.elasticity() * strain);
		}
		for (const PointLoad& load : block.loads)
			energy_.loads += load.force.dot(displacementAt(load.position - block.centroid, D));
		for (const FixedPoint& point : block.fixedPoints) {
			const double stiffness = fixedPointStiffness(point, block, settings);
			const Vector3 u = displacementAt(point.position - block.centroid, D);
			energy_.loads += stiffness * (point.anchor - point.position - gamma * u).dot(u);
		}
	}
	// Contacts: their springs' energy at the start of this step in the
	// accepted states against what the last step ended with.
	double start = 0, end = 0;
	for (const Contact& contact : store_.contacts()) {
		const int bi = contact.key.blockI, bj = contact.key.blockJ;
		const ContactStepEnergy e = contactStepEnergy(contact, blocks_[bi], blocks_[bj], solutionOf(bi), solutionOf(bj));
		start += e.start;
		end += e.end;
		energy_.damping += e.damping;
		energy_.friction += e.friction;
	}
	energy_.contactChanges += start - energy_.contact;
	energy_.contact = end;
}

double World::step(const IntegratorSettings& settings) {
	validateSettings(settings);
	if (settings.threads > 0) omp_set_num_threads(settings.threads);
	if (steps_ == 0 && settings.startFromRest && !settleTried_) settle(settings);
	settleTried_ = true;
	const double dt = advance(settings);
	stats_.settleSteps = settleSteps_;
	stats_.settledBlocks = settledBlocks_;
	stats_.settleConverged = settleConverged_;
	return dt;
}

void World::markSettlingBlocks() {
	// Blocks joined by touching contacts (closed at D = 0: penetrating or
	// flush, or bonded) form components; a component settles when it holds a
	// fixed block or a fixed point and all its moving blocks are at rest.
	const int count = blockCount();
	std::vector<int> root(count);
	for (int b = 0; b < count; ++b) root[b] = b;
	auto find = [&](int b) {
		while (root[b] != b) b = root[b] = root[root[b]];
		return b;
	};
	for (const Contact& contact : store_.contacts()) {
		if (!contact.normal.valid || contact.normal.d0 > 0) continue;
		const int a = find(contact.key.blockI), b = find(contact.key.blockJ);
		if (a != b) root[std::max(a, b)] = std::min(a, b);
	}
	std::vector<char> supported(count, 0), moving(count, 0);
	for (int b = 0; b < count; ++b) {
		const Block& block = blocks_[b];
		const int r = find(b);
		if (block.fixed || !block.fixedPoints.empty()) supported[r] = 1;
		if (!block.fixed && !block.velocity.isZero()) moving[r] = 1;
	}
	frozen_.assign(count, 1);
	settledBlocks_ = 0;
	for (int b = 0; b < count; ++b) {
		const int r = find(b);
		if (blocks_[b].fixed || !supported[r] || moving[r]) continue;
		frozen_[b] = 0;
		++settledBlocks_;
	}
}

void World::settle(const IntegratorSettings& settings) {
	// Static steps bring the blocks to rest; everything a step advances is
	// kept aside and put back, so the settling takes no time, no step and no
	// energy of the account: it sets the scene's initial state.
	const std::vector<Block> placed = blocks_;
	const ContactStore placedContacts = store_;
	const double time = time_, nextTimeStep = nextTimeStep_;
	const long steps = steps_, misses = displacementLimitMisses_, failures = openCloseFailures_;
	IntegratorSettings statics = settings;
	statics.velocityRatio = 0;
	statics.newmarkBeta = 0.5;
	statics.newmarkGamma = 1;
	statics.timeStepGrowth = 1;
	// A step long enough that inertia weighs at most 1e-3 of every block's
	// stiffnesses: of its contact springs (2 m / dt^2 = 1e-3 kn) and, for a
	// deformable block, of its strain modes (the mass of a uniform strain,
	// rho J ~ rho V L^2 / 12, against V E: rho L^2 / (6 E dt^2) = 1e-3).
	// Each static step then closes all but about 1e-3 of the distance to
	// equilibrium. (Sized by the contacts alone, a block 1000 times stiffer
	// in its contacts than in itself needed more than 12 steps.)
	double longest = settings.maxTimeStep;
	for (const Block& block : blocks_) {
		if (block.fixed) continue;
		const double kn = settings.contactPenaltyFactor * block.material.young * block.size;
		longest = std::max(longest, std::sqrt(2000 * block.mass / kn));
		if (!block.rigid)
			longest = std::max(longest, std::sqrt(1000 * block.density() * block.size * block.size /
			                                      (6 * block.material.young)));
	}
	statics.maxTimeStep = longest;
	settling_ = true;
	frictionScale_ = kSettleFrictionScale;
	frozen_.clear();
	settleSteps_ = 0;
	settleConverged_ = false;
	double first = -1;
	for (int k = 0; k < kSettleSteps; ++k) {
		nextTimeStep_ = longest;
		try {
			advance(statics);
		} catch (const std::exception&) {
			// No static solution with these contacts (a system no inertia
			// keeps definite): the scene starts as placed.
			settleConverged_ = false;
			++settleSteps_;
			break;
		}
		++settleSteps_;
		// The settling blocks only: a frozen one (moving, or unsupported)
		// keeps its velocity.
		for (int b = 0; b < blockCount(); ++b)
			if (!blocks_[b].fixed && !frozen_[b]) blocks_[b].velocity.setZero();
		const double moved = stats_.maxDisplacement;
		if (first < 0) first = moved;
		if (settledBlocks_ == 0) break;
		if (moved <= kSettleTolerance * first) {
			settleConverged_ = true;
			break;
		}
	}
	settling_ = false;
	frictionScale_ = 1;
	frozen_.clear();
	if (settledBlocks_ == 0) settleSteps_ = 0;  // nothing to settle: not tried
	if (!settleConverged_) {
		blocks_ = placed;
		store_ = placedContacts;
		collider_->setPairReuse(false);  // its cache saw the moved blocks
		settledBlocks_ = 0;
	}
	// The account starts here: the springs' energy is the settled state's.
	const double springs = energy_.contact;
	energy_ = EnergyAccount{};
	if (settleConverged_) energy_.contact = springs;
	time_ = time;
	nextTimeStep_ = nextTimeStep;
	steps_ = steps;
	displacementLimitMisses_ = misses;
	openCloseFailures_ = failures;
}

double World::advance(const IntegratorSettings& settings) {
	const auto stepStart = Clock::now();
	StepStatistics stats;
	stats.blocks = blockCount();
	stats.allowedDisplacement = settings.maxDisplacement > 0 ? settings.maxDisplacement
	                                                         : settings.maxDisplacementRatio * sceneHalfSize();
	stats.contactDistance = settings.contactDistance > 0 ? settings.contactDistance
	                                                     : settings.contactDistanceFactor * stats.allowedDisplacement;
	detectContacts(settings, stats);
	if (settling_ && frozen_.empty()) markSettlingBlocks();
	moving_.clear();
	movingIndex_.assign(blockCount(), -1);
	for (int i = 0; i < blockCount(); ++i) {
		if (blocks_[i].fixed || (!frozen_.empty() && frozen_[i])) continue;
		movingIndex_[i] = static_cast<int>(moving_.size());
		moving_.push_back(i);
	}
	if (settling_) {
		// Contacts of two frozen (or fixed) blocks carry nothing while
		// settling; left out, the first step finds them as new.
		std::vector<Contact>& found = store_.contacts();
		found.erase(std::remove_if(found.begin(), found.end(),
		                           [&](const Contact& c) {
			                           return movingIndex_[c.key.blockI] < 0 && movingIndex_[c.key.blockJ] < 0;
		                           }),
		            found.end());
		stats.contacts = static_cast<int>(found.size());
	}
	const int n = static_cast<int>(moving_.size());
	stats.movingBlocks = n;
	stats.fixedBlocks = blockCount() - n;
	stats.staticAnalysis = settings.velocityRatio == 0;
	blockUnknowns_.resize(n);
	for (int k = 0; k < n; ++k) {
		const Block& b = blocks_[moving_[k]];
		blockUnknowns_[k] = b.unknowns();
		stats.unknowns += b.unknowns();
		stats.rigidBlocks += b.rigid;
		stats.strainUnknowns += b.unknowns() - kRigidBlockDofs;
	}
	solutions_.resize(n);
	std::vector<Contact>& contacts = store_.contacts();

	double dt = nextTimeStep_ > 0 ? std::min(nextTimeStep_, settings.maxTimeStep) : settings.maxTimeStep;

	for (int attempt = 0;; ++attempt) {
		// The blocks' own systems depend on dt: assembled anew in each attempt.
		ownSystems_.clear();
		ownSystemOf_.assign(n, -1);
		solvedAlone_.assign(n, 0);
		// assembleBlock adds a body force only for non-zero gravity.
		if (!settings.gravity.isZero()) stats.bodyForceBlocks += n;

		// Open-close iteration: Newton's method on the step's energy (the
		// blocks' quadratic energy plus every contact's compression-only
		// normal spring and Coulomb-limited tangential spring; see
		// ContactEquations.hpp), in passes. Within a pass each contact's
		// friction limit is fixed, so the energy is one convex function:
		// each solve minimises the contacts' model at the states of the
		// current iterate, the states are evaluated at the new iterate, and
		// once a contact has swung back (or the pass runs long) a line search
		// makes every iterate lower the energy, so the pass cannot cycle. A
		// pass has converged when no state changes and the slipping
		// contacts' forces agree with their model: every closed contact is
		// then in compression and every open one apart, exactly the
		// gradients the energy account books, so the step creates no energy
		// (World::accountStep). Then the limits are set from the normal
		// forces found, and another pass is made while they change by more
		// than kLimitTolerance (at most kLimitPasses). The hold-closed and
		// friction-switch rules this replaces held contacts in tension and
		// created energy (a stiff pile gained up to 36%).
		iterate_.assign(n, Vector12::Zero());
		keptTerms_.clear();
		keptTermsOf_.assign(contacts.size(), -1);
		for (Contact& contact : contacts) {
			startTrial(contact, steps_ == 0);
			const int bi = contact.key.blockI, bj = contact.key.blockJ;
			// The first pass's limit from the normal force at the start of
			// the step (its gap now), not the one the contact ended the last
			// step with: a corner that bounced off keeps no friction.
			evaluateContact(contact, blocks_[bi], blocks_[bj], solutionOf(bi), solutionOf(bj));
			updateFrictionLimit(contact, true);
			evaluateContact(contact, blocks_[bi], blocks_[bj], solutionOf(bi), solutionOf(bj));
		}
		computeStartAccelerations(settings);
		// The blocks that contacts join (open ones too: their energy counts
		// once they close) form groups whose energies are independent: each
		// group iterates, searches and converges on its own, so a block
		// elsewhere in the scene cannot change another's trajectory, not even
		// by round-off. A converged group's iterate is no longer moved.
		groupContacts();
		group_.reset(n);
		for (const Contact& contact : contacts) group_.hasContacts[contactGroup_[&contact - contacts.data()]] = 1;
		bool converged = false, structureStale = true;
		int iterations = 0, changes = 0;
		while (iterations < std::max(1, settings.maxOpenCloseIterations)) {
			auto phase = Clock::now();
			const bool rebuilt = structureStale;
			if (structureStale) {
				buildSystemStructure(n, stats);
				assembleOwnSystems(settings, dt);
			}
			structureStale = false;
			coupled_.reset(ownSystems_, ownSystemOf_);
			assembleContacts(stats);
			stats.timeAssembly += secondsSince(phase);
			phase = Clock::now();
			// Which blocks are alone changes only with the structure.
			if (rebuilt) solveAloneBlocks(settings, dt);
			coupled_.solve(solutions_, kMinBlocksForThreads);
			stats.solvedUnknowns = coupled_.solvedUnknowns() + aloneUnknowns_;
			if (lineSearch(settings, dt) < 1) ++stats.lineSearches;
			stats.timeSolve += secondsSince(phase);
			++iterations;
			group_.startIteration();
			for (std::size_t c = 0; c < contacts.size(); ++c) {
				Contact& contact = contacts[c];
				const int g = contactGroup_[c];
				if (group_.done[g]) continue;
				const int bi = contact.key.blockI, bj = contact.key.blockJ;
				const Vector12& Di = solutionOf(bi);
				const Vector12& Dj = solutionOf(bj);
				const Vector3 model = tangentialForce(contact, blocks_[bi], blocks_[bj], Di, Dj);
				const double normalMiss = normalModelError(contact, Di, Dj);
				const bool wasClosed = isClosed(contact);
				if (evaluateContact(contact, blocks_[bi], blocks_[bj], Di, Dj)) {
					++group_.changes[g];
					// Only closed contacts carry normal terms: opening and
					// closing change which blocks the system couples.
					if (wasClosed != isClosed(contact)) {
						structureStale = true;
						if (++contact.openCloseChanges >= 2) group_.swungBack[g] = 1;
					}
				}
				// A contact that closes with no limit takes the limit of its
				// normal force now, once per pass (so the pass's energy changes
				// a finite number of times): frictionless until the next pass,
				// a block landing on a much larger one was held sideways by its
				// inertia alone, and the system's Cholesky failed on round-off
				// at five decades of scale.
				if (isClosed(contact) && !(contact.slipLimit > 0) && contact.trial.normalForce > 0 &&
				    contact.frictionTangent > 0) {
					updateFrictionLimit(contact, true);
					evaluateContact(contact, blocks_[bi], blocks_[bj], Di, Dj);
					++group_.changes[g];
				}
				// The force scale of the group: its largest normal force, or
				// friction limit (an open contact keeps its limit for the pass,
				// so a group may slip with no normal force at all).
				group_.largestNormalForce[g] = std::max(
				    {group_.largestNormalForce[g], std::abs(contact.trial.normalForce), contact.slipLimit});
				group_.forceChange[g] =
				    std::max({group_.forceChange[g], normalMiss,
				              (tangentialForce(contact, blocks_[bi], blocks_[bj], Di, Dj) - model).norm()});
			}
			// Groups whose pass converged: their limits against the normal
			// forces found; done when they agree, else another pass. (Limits
			// that follow the normal forces at every solve instead, as Shi's
			// friction does, settled most steps in fewer solves but cycled in
			// others and, accepted unsettled, lost a sliding cube a fifth of
			// its speed in its first step.)
			for (std::size_t c = 0; c < contacts.size(); ++c) {
				const int g = contactGroup_[c];
				if (group_.done[g] || !group_.passConverged(g, kNewtonTolerance)) continue;
				const double change = updateFrictionLimit(contacts[c], false);
				group_.limitChange[g] = std::max(group_.limitChange[g], change);
				group_.largestLimit[g] = std::max(group_.largestLimit[g], contacts[c].slipLimit + change);
			}
			changes = 0;
			bool allDone = true;
			for (int g = 0; g < n; ++g) {
				if (group_.done[g]) continue;
				changes += group_.changes[g];
				if (!group_.hasContacts[g]) {
					group_.done[g] = 1;  // no contact: its own solve is its answer
					continue;
				}
				const bool converged = group_.passConverged(g, kNewtonTolerance);
				const bool settled = group_.limitChange[g] <= kLimitTolerance * group_.largestLimit[g];
				// A converged pass is accepted with its limits unsettled after
				// kLimitPasses passes, or once three quarters of the step's
				// solves are spent: it is energy-safe (every limit >= 0
				// dissipates), and a cut would throw every solve away. In a
				// pile of 30 stiff cubes a contact's limit can swing between
				// its closed and open values pass after pass.
				const bool late = iterations >= (3 * settings.maxOpenCloseIterations) / 4;
				if (converged && (settled || late || group_.passes[g] + 1 >= kLimitPasses)) {
					group_.done[g] = 1;
					if (!settled) ++stats.limitsUnsettled;
					continue;
				}
				allDone = false;
				if (!converged) continue;
				group_.newPass[g] = 1;
				++group_.passes[g];
				++stats.limitPasses;
				group_.passSolves[g] = 0;
			}
			if (allDone) {
				converged = true;
				break;
			}
			for (std::size_t c = 0; c < contacts.size(); ++c) {
				Contact& contact = contacts[c];
				if (!group_.newPass[contactGroup_[c]]) continue;
				// Which contacts carry terms may change with the limits (an
				// open contact with a limit keeps its tangential spring).
				const bool hadTerms = isClosed(contact) || contact.slipLimit > 0;
				updateFrictionLimit(contact, true);
				if (hadTerms != (isClosed(contact) || contact.slipLimit > 0)) structureStale = true;
				const int bi = contact.key.blockI, bj = contact.key.blockJ;
				evaluateContact(contact, blocks_[bi], blocks_[bj], solutionOf(bi), solutionOf(bj));
			}
		}
		solutions_ = iterate_;
		stats.openCloseIterations = iterations;
		stats.openCloseIterationsTotal += iterations;
		stats.stateChanges = changes;

		double largest = 0;
#pragma omp parallel for schedule(static) reduction(max : largest) if (n >= kMinBlocksForThreads)
		for (int k = 0; k < n; ++k) largest = std::max(largest, largestVertexDisplacement(blocks_[moving_[k]], solutions_[k]));
		if (!std::isfinite(largest)) {
			std::ostringstream message;
			message << "the DDA step produced a non-finite displacement (dt = " << dt << " s)";
			throw std::runtime_error(message.str());
		}
		stats.maxDisplacement = largest;

		if (!converged) {
			if (attempt == settings.maxStepCuts) {
				++openCloseFailures_;
				break;
			}
			dt *= settings.openCloseShrink;
			++stats.openCloseCuts;
			++stats.stepCuts;
			continue;
		}
		if (largest <= stats.allowedDisplacement || stats.allowedDisplacement <= 0) break;
		if (attempt == settings.maxStepCuts) {
			++displacementLimitMisses_;
			break;
		}
		const double shrink = std::clamp(settings.timeStepSafety * stats.allowedDisplacement / largest,
		                                 settings.minTimeStepShrink, settings.maxTimeStepShrink);
		dt *= shrink;
		++stats.stepCuts;
	}

	gravity_ = settings.gravity;
	accountStep(settings);
	const auto phase = Clock::now();
	// Contacts first (forces from the accepted solution, anchors carried along
	// with their blocks), then the blocks themselves.
	motions_.resize(n);
	for (int k = 0; k < n; ++k) motions_[k] = blockMotion(blocks_[moving_[k]], solutions_[k]);
	for (Contact& contact : contacts) {
		const int bi = contact.key.blockI, bj = contact.key.blockJ;
		finishContact(contact, blocks_[bi], blocks_[bj], solutionOf(bi), solutionOf(bj));
		ContactHistory& trial = contact.trial;
		contact.point = movingIndex_[bi] >= 0 ? motions_[movingIndex_[bi]](contact.geometry.pointI) : contact.geometry.pointI;
		if (trial.state != ContactState::Open) {
			if (movingIndex_[bi] >= 0) trial.anchorI = motions_[movingIndex_[bi]](trial.anchorI);
			if (movingIndex_[bj] >= 0) trial.anchorJ = motions_[movingIndex_[bj]](trial.anchorJ);
		}
		if (trial.state != ContactState::Open) {
			++stats.closedContacts;
			stats.slidingContacts += trial.state == ContactState::Sliding;
			stats.maxPenetration =
			    std::max(stats.maxPenetration, -contactGap(contact, solutionOf(bi), solutionOf(bj)));
		}
		contact.history = trial;
		stats.bondedContacts += trial.bonded;
	}
#pragma omp parallel for schedule(static) if (n >= kMinBlocksForThreads)
	for (int k = 0; k < n; ++k) {
		Block& block = blocks_[moving_[k]];
		applyStep(block, solutions_[k],
		          endVelocity(solutions_[k], startVelocity(block, settings), dt));
	}
	stats.timeUpdate = secondsSince(phase);

	nextTimeStep_ = std::min(settings.maxTimeStep, dt * settings.timeStepGrowth);
	time_ += dt;
	++steps_;
	stats.dt = dt;
	stats.displacementLimitMisses = displacementLimitMisses_;
	stats.openCloseFailures = openCloseFailures_;
	stats.timeTotal = secondsSince(stepStart);
	stats_ = stats;
	return dt;
}

}  // namespace dda
