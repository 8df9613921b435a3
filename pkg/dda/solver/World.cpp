#include "World.hpp"

#include "dda/geometry/MassProperties.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

namespace dda {

namespace {
using Clock = std::chrono::steady_clock;
// Per-block loops run in parallel only from this many blocks on: waking an
// OpenMP team costs tens of microseconds, more than a few blocks' work.
constexpr int kMinBlocksForThreads = 64;
double secondsSince(Clock::time_point start) {
	return std::chrono::duration<double>(Clock::now() - start).count();
}
void requireFinite(const Vector3& v, const char* what) {
	if (!v.allFinite()) {
		std::ostringstream message;
		message << what << " must be finite, got (" << v.x() << ", " << v.y() << ", " << v.z() << ")";
		throw InputError(message.str());
	}
}
}  // namespace

int World::addBlock(const std::vector<Vector3>& points, const Material& material, bool fixed) {
	validateMaterial(material);
	auto shape = std::make_shared<const ConvexPolyhedron>(buildConvexPolyhedron(points));
	const MassProperties properties = computeMassProperties(shape->vertices, shape->faces);
	Block block;
	block.shape = shape;
	block.vertices = shape->vertices;
	block.centroid = properties.centroid;
	block.volume = properties.volume;
	block.secondMoment = properties.secondMoment;
	block.mass = material.density * properties.volume;
	block.size = std::cbrt(properties.volume);
	block.material = material;
	block.elasticity = elasticityMatrix(material.young, material.poisson);
	block.fixed = fixed;
	blocks_.push_back(std::move(block));
	return blockCount() - 1;
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
	block(index).fixedPoints.push_back({position, position, stiffness});
}

void World::addPointLoad(int index, const Vector3& position, const Vector3& force) {
	requireFinite(position, "a point load's position");
	requireFinite(force, "a point load's force");
	block(index).loads.push_back({position, force});
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
	block(index).stress = stress;
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

void World::validateSettings(const IntegratorSettings& s) const {
	std::ostringstream message;
	if (!(std::isfinite(s.maxTimeStep) && s.maxTimeStep > 0))
		message << "dt must be positive and finite, got " << s.maxTimeStep << " s";
	else if (!s.gravity.allFinite())
		message << "gravity must be finite";
	else if (!(s.velocityRatio >= 0 && s.velocityRatio <= 1))
		message << "velocityRatio must lie in [0, 1], got " << s.velocityRatio;
	else if (!(std::isfinite(s.maxDisplacement)))
		message << "maxDisplacement must be finite, got " << s.maxDisplacement << " m";
	else if (!(s.maxDisplacementRatio > 0 && std::isfinite(s.maxDisplacementRatio)))
		message << "maxDisplacementRatio must be positive, got " << s.maxDisplacementRatio;
	else if (!(s.minTimeStepShrink > 0 && s.minTimeStepShrink <= s.maxTimeStepShrink && s.maxTimeStepShrink < 1))
		message << "time-step shrink factors must satisfy 0 < min <= max < 1";
	else if (!(s.timeStepGrowth >= 1 && std::isfinite(s.timeStepGrowth)))
		message << "timeStepGrowth must be >= 1, got " << s.timeStepGrowth;
	else if (s.maxStepCuts < 0)
		message << "maxStepCuts must be >= 0, got " << s.maxStepCuts;
	else if (!(s.fixedPointPenaltyFactor > 0 && std::isfinite(s.fixedPointPenaltyFactor)))
		message << "fixedPointPenaltyFactor must be positive, got " << s.fixedPointPenaltyFactor;
	else
		return;
	throw InputError(message.str());
}

double World::step(const IntegratorSettings& settings) {
	validateSettings(settings);
	const auto stepStart = Clock::now();
	if (settings.threads > 0) omp_set_num_threads(settings.threads);

	StepStatistics stats;
	stats.blocks = blockCount();
	moving_.clear();
	for (int i = 0; i < blockCount(); ++i)
		if (!blocks_[i].fixed) moving_.push_back(i);
	const int n = static_cast<int>(moving_.size());
	stats.movingBlocks = n;
	stats.unknowns = kBlockDofs * n;
	systems_.resize(n);
	solutions_.resize(n);
	startVelocities_.resize(n);
	for (int k = 0; k < n; ++k) startVelocities_[k] = startVelocity(blocks_[moving_[k]], settings);

	stats.allowedDisplacement = settings.maxDisplacement > 0 ? settings.maxDisplacement
	                                                         : settings.maxDisplacementRatio * sceneHalfSize();
	double dt = nextTimeStep_ > 0 ? std::min(nextTimeStep_, settings.maxTimeStep) : settings.maxTimeStep;

	for (int attempt = 0;; ++attempt) {
		auto phase = Clock::now();
#pragma omp parallel for schedule(static) if (n >= kMinBlocksForThreads)
		for (int k = 0; k < n; ++k) assembleBlock(blocks_[moving_[k]], settings, dt, systems_[k]);
		stats.timeAssembly += secondsSince(phase);

		phase = Clock::now();
		double largest = 0;
#pragma omp parallel for schedule(static) reduction(max : largest) if (n >= kMinBlocksForThreads)
		for (int k = 0; k < n; ++k) {
			solutions_[k] = solveBlock(blocks_[moving_[k]], systems_[k]);
			largest = std::max(largest, largestVertexDisplacement(blocks_[moving_[k]], solutions_[k]));
		}
		stats.timeSolve += secondsSince(phase);

		if (!std::isfinite(largest)) {
			std::ostringstream message;
			message << "the DDA step produced a non-finite displacement (dt = " << dt << " s)";
			throw std::runtime_error(message.str());
		}
		stats.maxDisplacement = largest;
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

	const auto phase = Clock::now();
#pragma omp parallel for schedule(static) if (n >= kMinBlocksForThreads)
	for (int k = 0; k < n; ++k) applyStep(blocks_[moving_[k]], solutions_[k], startVelocities_[k], dt);
	stats.timeUpdate = secondsSince(phase);

	nextTimeStep_ = std::min(settings.maxTimeStep, dt * settings.timeStepGrowth);
	time_ += dt;
	++steps_;
	stats.dt = dt;
	stats.displacementLimitMisses = displacementLimitMisses_;
	stats.timeTotal = secondsSince(stepStart);
	stats_ = stats;
	return dt;
}

}  // namespace dda
