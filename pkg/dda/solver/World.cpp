// The World facade (World.hpp): its blocks, their loads and velocities, the
// settings' checks, and the order of a step (World::step, advance). The parts
// a step runs have their own files (doc/DESIGN.md, "Source layout"):
// ContactDetection, OpenClose, TimeStepControl, EnergyAccount, Settling.
#include "World.hpp"

#include "ContactEquations.hpp"
#include "StepClock.hpp"
#include "dda/geometry/ConvexParts.hpp"
#include "dda/geometry/MassProperties.hpp"
#include "dda/core/CapacityBytes.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace dda {

namespace {
void requireFinite(const Vector3& v, const char* what) {
	if (!v.allFinite()) {
		std::ostringstream message;
		message << what << " must be finite, got (" << v.x() << ", " << v.y() << ", " << v.z() << ")";
		throw InputError(message.str());
	}
}
}  // namespace

int World::addBlock(const std::vector<Vector3>& points, const Material& material, bool fixed, bool rigid) {
	Block block = makeBlock(points, material, fixed, rigid);
	block.shape = topologies_.intern(std::move(block.shape));
	blocks_.push_back(std::move(block));
	return blockCount() - 1;
}

int World::addConcaveBlock(const std::vector<std::vector<Vector3>>& parts, const Material& material, bool fixed,
                           bool rigid) {
	std::vector<Block> made = makeConcaveBlock(parts, material, fixed, rigid);
	const int first = blockCount();
	reserveBlocks(static_cast<int>(made.size()));
	for (Block& block : made) {
		block.shape = topologies_.intern(std::move(block.shape));
		if (block.body >= 0) block.body += first;
		blocks_.push_back(std::move(block));
	}
	return first;
}

std::vector<Block> makeConcaveBlock(const std::vector<std::vector<Vector3>>& parts, const Material& material,
                                    bool fixed, bool rigid) {
	validateMaterial(material);
	if (parts.empty()) throw InputError("a concave block needs at least one part");
	std::vector<ConvexPolyhedron> polyhedra;
	std::vector<Block> blocks;
	std::vector<MassProperties> properties;
	for (std::size_t p = 0; p < parts.size(); ++p) {
		try {
			blocks.push_back(makeBlock(parts[p], material, fixed, rigid));
		} catch (const InputError& error) {
			throw InputError("part " + std::to_string(p) + " of the concave block: " + error.what());
		}
		const Block& b = blocks.back();
		ConvexPolyhedron& polyhedron = polyhedra.emplace_back();  // the part's hull, as makeBlock made it
		static_cast<PolyhedronTopology&>(polyhedron) = *b.shape;
		polyhedron.vertices = b.vertices;
		properties.push_back(MassProperties{b.volume, b.centroid, b.secondMoment});
	}
	checkConvexParts(polyhedra);
	if (blocks.size() == 1) return blocks;
	// The body carries the whole block's mass properties; each later part
	// its own volume, centroid and second moments (moved with it), no mass.
	const MassProperties whole = unionMassProperties(properties);
	Block& body = blocks.front();
	body.centroid = whole.centroid;
	body.volume = whole.volume;
	body.secondMoment = whole.secondMoment;
	body.mass = material.density * whole.volume;
	body.size = std::cbrt(whole.volume);
	body.partCount = static_cast<int>(blocks.size());
	for (std::size_t p = 1; p < blocks.size(); ++p) {
		blocks[p].body = 0;
		blocks[p].mass = 0;
		blocks[p].size = body.size;
	}
	return blocks;
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
	block.centroid = block.initialCentroid = properties.centroid;
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

Block& World::bodyBlock(int index) {
	block(index);  // checks the index
	return blocks_[bodyOf(index)];
}

void World::addFixedPoint(int index, const Vector3& position, double stiffness) {
	requireFinite(position, "a fixed point");
	if (!std::isfinite(stiffness)) throw InputError("fixed point stiffness must be finite");
	Block& b = bodyBlock(index);
	if (b.fixed) throw InputError("block " + std::to_string(index) + " is fixed: a fixed point would have no effect");
	b.fixedPoints.push_back({position, position, stiffness});
}

void World::addPointLoad(int index, const Vector3& position, const Vector3& force) {
	requireFinite(position, "a point load's position");
	requireFinite(force, "a point load's force");
	Block& b = bodyBlock(index);
	if (b.fixed) throw InputError("block " + std::to_string(index) + " is fixed: a point load would have no effect");
	b.loads.push_back({position, force});
}

void World::setVelocity(int index, const Vector3& velocity, const Vector3& angularVelocity) {
	requireFinite(velocity, "velocity");
	requireFinite(angularVelocity, "angular velocity");
	Block& b = bodyBlock(index);
	if (b.fixed && !(velocity.isZero() && angularVelocity.isZero()))
		throw InputError("a fixed block cannot be given a velocity");
	b.velocity.head<3>() = velocity;
	b.velocity.segment<3>(3) = angularVelocity;
}

void World::setStress(int index, const Vector6& stress) {
	if (!stress.allFinite()) throw InputError("initial stress must be finite");
	Block& b = bodyBlock(index);
	if (b.rigid && !stress.isZero()) {
		std::ostringstream message;
		message << "block " << index << " is rigid: it has no strain and carries no stress, so it cannot be given an "
		        << "initial stress (got (" << stress.transpose() << ") Pa)";
		throw InputError(message.str());
	}
	b.stress = stress;
}

double World::motionHalfSize() {
	if (motionSizedBlocks_ != blockCount()) {
		motionHalfSize_ = TimeStepControl::motionHalfSize(
		    blockCount(), [this](int k) -> const std::vector<Vector3>& { return blocks_[k].vertices; },
		    [this](int k) { return blocks_[k].fixed; });
		motionSizedBlocks_ = blockCount();
	}
	return motionHalfSize_;
}

void World::setCollider(std::unique_ptr<Collider> collider) {
	if (!collider) throw InputError("a collider is required");
	collider_ = std::move(collider);
}

World::MemoryUse World::memoryUse() const {
	MemoryUse use;
	use.collider = collider_->memoryBytes();
	use.contacts = store_.memoryBytes();
	use.narrowPhase = detection_.memoryBytes();
	use.solver = openClose_.memoryBytes() + capacityBytes(motions_) + capacityBytes(blockEnergies_) +
	             capacityBytes(contactEnergies_);
	return use;
}

namespace {
// OpenMP's thread count (settings.threads) for the span of one step; the
// calling thread's count before it is given back on leaving, by return or by
// exception. The count is a setting of the calling thread that YADE's own
// parallel loops read too, and YADE sizes a scene's ForceContainer by it when
// the scene is made: a DDA step that set 1 in the main thread (O.step()) and
// left it made the next scene's container one buffer wide, and YADE's
// InteractionLoop, run with 2 threads, then wrote past it (a segfault in
// ForceContainer::addForce of a mixed scene).
class StepThreadCount {
public:
	explicit StepThreadCount(int threads) : previous_(omp_get_max_threads()), set_(threads > 0) {
		if (set_) omp_set_num_threads(threads);
	}
	~StepThreadCount() {
		if (set_) omp_set_num_threads(previous_);
	}
	StepThreadCount(const StepThreadCount&) = delete;
	StepThreadCount& operator=(const StepThreadCount&) = delete;

private:
	int previous_;
	bool set_;
};
}  // namespace

double World::step(const IntegratorSettings& settings) {
	validateSettings(settings);
	const StepThreadCount threadCount(settings.threads);
	if (steps_ == 0 && settings.startFromRest && !settleTried_) settle(settings);
	settleTried_ = true;
	const double dt = advance(settings);
	stats_.settleSteps = settleSteps_;
	stats_.settleSolves = settleSolves_;
	stats_.settleLimitPasses = settleLimitPasses_;
	stats_.settledBlocks = settledBlocks_;
	stats_.settleConverged = settleConverged_;
	return dt;
}

double World::advance(const IntegratorSettings& settings) {
	const auto stepStart = Clock::now();
	StepStatistics stats;
	stats.blocks = blockCount();
	stats.allowedDisplacement = TimeStepControl::allowedDisplacement(settings, [this] { return motionHalfSize(); });
	stats.contactDistance = stepContactDistance(settings, stats.allowedDisplacement);
	detection_.detect(blocks_, *collider_, store_, settings, frictionScale_, stats);
	if (settling_ && frozen_.empty()) markSettlingBlocks();
	openClose_.selectMovingBlocks(blocks_, frozen_, stats);
	if (settling_) dropFrozenContacts(stats);
	stats.staticAnalysis = settings.velocityRatio == 0;
	openClose_.setPrescribed(shaking() ? &prescribed_ : nullptr);
	if (shaking())
		for (const ShakenGroup& group : baseMotions_) stats.shakenBlocks += static_cast<int>(group.blocks.size());
	const double dt = solveStep(settings, stats);

	gravity_ = settings.gravity;
	accountStep(settings, dt);
	moveContactsAndBlocks(settings, dt, stats);

	timeStep_.stepTaken(settings, dt, stats.maxDisplacement, stats.allowedDisplacement);
	time_ += dt;
	++steps_;
	stats.dt = dt;
	stats.displacementLimitMisses = timeStep_.displacementLimitMisses();
	stats.openCloseFailures = timeStep_.openCloseFailures();
	stats.timeTotal = secondsSince(stepStart);
	stats_ = stats;
	return dt;
}

double World::solveStep(const IntegratorSettings& settings, StepStatistics& stats) {
	std::vector<Contact>& contacts = store_.contacts();
	double dt = timeStep_.firstTry(settings);
	for (int attempt = 0;; ++attempt) {
		// The shaken blocks' displacement over this attempt's dt (a cut step
		// takes its own), part of the step's largest.
		if (shaking()) prescribeMotions(dt);
		const bool converged = openClose_.solve(blocks_, contacts, settings, dt, steps_ == 0, stats);
		double largest = openClose_.largestDisplacement(blocks_);
		if (shaking()) largest = std::max(largest, prescribedLargest_);
		if (!std::isfinite(largest)) {
			std::ostringstream message;
			message << "the DDA step produced a non-finite displacement (dt = " << dt << " s)";
			throw std::runtime_error(message.str());
		}
		stats.maxDisplacement = largest;
		if (timeStep_.accept(attempt, converged, largest, openClose_.smallestJacobian(blocks_), settings, dt, stats))
			return dt;
	}
}

void World::moveContactsAndBlocks(const IntegratorSettings& settings, double dt, StepStatistics& stats) {
	const auto phase = Clock::now();
	const std::vector<int>& moving = openClose_.moving();
	const int n = static_cast<int>(moving.size());
	// Contacts first (forces from the accepted solution, anchors carried along
	// with their blocks), then the blocks themselves.
	motions_.resize(n);
#pragma omp parallel for schedule(static) if (n >= kMinBlocksForThreads)
	for (int k = 0; k < n; ++k) motions_[k] = blockMotion(blocks_[moving[k]], openClose_.solution(k));
	// Each contact writes only itself; the counts are integer sums and the
	// deepest penetration a max from the same start (+0 or the step's value:
	// a -0 never replaces it), so any split over threads gives the same.
	std::vector<Contact>& contacts = store_.contacts();
	const int contactCount = static_cast<int>(contacts.size());
	const bool shaking = this->shaking();
	long closedCount = 0, slidingCount = 0, bondedCount = 0;
	double deepest = stats.maxPenetration;
#pragma omp parallel if (contactCount >= kMinContactsForThreads)
	{
		long closedHere = 0, slidingHere = 0, bondedHere = 0;
		double deepestHere = stats.maxPenetration;
#pragma omp for schedule(static)
		for (int c = 0; c < contactCount; ++c) {
			Contact& contact = contacts[c];
			const int bi = contact.bodyI, bj = contact.bodyJ;
			const int mi = openClose_.movingIndex(bi), mj = openClose_.movingIndex(bj);
			const Vector12& Di = openClose_.solutionOf(bi);
			const Vector12& Dj = openClose_.solutionOf(bj);
			finishContact(contact, blocks_[bi], blocks_[bj], Di, Dj);
			ContactHistory& trial = contact.trial;
			contact.point = mi >= 0 ? motions_[mi](contact.geometry.pointI) : contact.geometry.pointI;
			if (shaking && blocks_[bi].shaken) contact.point += Di.head<3>();  // its known translation
			if (trial.state != ContactState::Open) {
				if (mi >= 0) trial.anchorI = motions_[mi](trial.anchorI);
				if (mj >= 0) trial.anchorJ = motions_[mj](trial.anchorJ);
				if (shaking && blocks_[bi].shaken) trial.anchorI += Di.head<3>();
				if (shaking && blocks_[bj].shaken) trial.anchorJ += Dj.head<3>();
				++closedHere;
				slidingHere += trial.state == ContactState::Sliding;
				deepestHere = std::max(deepestHere, -contactGap(contact, Di, Dj));
			}
			contact.history = trial;
			bondedHere += trial.bonded;
		}
#pragma omp critical(ddaFinishContacts)
		{
			closedCount += closedHere;
			slidingCount += slidingHere;
			bondedCount += bondedHere;
			deepest = std::max(deepest, deepestHere);
		}
	}
	stats.closedContacts += static_cast<int>(closedCount);
	stats.slidingContacts += static_cast<int>(slidingCount);
	stats.bondedContacts += static_cast<int>(bondedCount);
	stats.maxPenetration = deepest;
#pragma omp parallel for schedule(static) if (n >= kMinBlocksForThreads)
	for (int k = 0; k < n; ++k) {
		Block& block = blocks_[moving[k]];
		applyStep(block, openClose_.solution(k),
		          endVelocity(openClose_.solution(k), startVelocity(block, settings), dt));
		for (int p = 1; p < block.partCount; ++p)
			movePart(blocks_[moving[k] + p], block, motions_[k], openClose_.solution(k));
	}
	if (shaking) moveShakenBlocks(dt);
	stats.timeUpdate = secondsSince(phase);
}

}  // namespace dda
