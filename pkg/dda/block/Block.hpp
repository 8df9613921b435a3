// State of one DDA block: its current geometry, mass properties, velocity in
// the 12 unknowns, stress, supports and loads. All quantities SI and global.
#pragma once

#include "Displacement.hpp"
#include "dda/geometry/ConvexPolyhedron.hpp"

#include <Eigen/Geometry>

#include <memory>
#include <string>
#include <vector>

namespace dda {

// Isotropic linear elastic block material, and the joint properties its
// contacts take (a contact uses the smaller friction angle of its two blocks,
// as YADE's frictional laws do).
struct Material {
	double density = 2600;     // kg/m^3, > 0
	double young = 1e9;        // Pa, > 0
	double poisson = 0.25;     // -, in (-1, 0.5)
	double frictionAngle = 0;  // rad, in [0, pi/2); 0 = frictionless joints
	// Joint bond strengths [Pa], >= 0: contacts closed when the scene starts
	// are bonded joints that resist shear up to cohesion x area beyond
	// friction and tension up to tensileStrength x area, until they break.
	double cohesion = 0;
	double tensileStrength = 0;
};

// Throws InputError naming the offending value.
void validateMaterial(const Material& material);

struct Block;
// The index of the block whose unknowns block `index` moves with: its body
// when it is a later part of a concave block (Block::body), else itself.
int bodyIndex(const std::vector<Block>& blocks, int index);
// A point strictly inside the block's own convex shape [m]: its centroid, or
// for a part of a concave block (whose centroid field is the whole block's
// when it is the body) the mean of its corners.
Vector3 interiorPoint(const Block& block);

// A penalty spring pulling a material point of the block back to its anchor.
struct FixedPoint {
	Vector3 position;  // current position of the material point [m]
	Vector3 anchor;    // where the spring holds it [m]
	double stiffness;  // [N/m]; <= 0: IntegratorSettings::fixedPointPenaltyFactor x E x size
};

// A constant force [N] (global direction) acting on a material point [m].
struct PointLoad {
	Vector3 position;
	Vector3 force;
};

struct Block {
	// Faces and edges, shared with the other blocks of the same topology
	// (World interns them, see TopologyPool).
	std::shared_ptr<const PolyhedronTopology> shape;
	std::vector<Vector3> initialVertices;           // as created [m]; saved, read by no step
	std::vector<Vector3> vertices;                  // current positions [m]
	Vector3 centroid = Vector3::Zero();             // [m]
	Vector3 initialCentroid = Vector3::Zero();      // of initialVertices [m]; derived, not saved
	double volume = 0;                              // [m^3]
	Matrix3 secondMoment = Matrix3::Zero();         // integral of d d^T dV [m^5]
	double mass = 0;                                // [kg], conserved
	Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  // accumulated since creation
	Vector12 velocity = Vector12::Zero();  // rates of the 12 unknowns [m/s, rad/s, 1/s]
	Vector6 stress = Vector6::Zero();      // (sxx, syy, szz, sxy, syz, szx) [Pa]
	Vector6 strain = Vector6::Zero();      // accumulated (ex, ey, ez, gxy, gyz, gzx) [-]
	Material material;
	// Elasticity matrix of the material [Pa]. Computed when asked (a dozen
	// flops) rather than stored: 288 bytes per block, 14 MB on 50,000 blocks.
	Matrix6 elasticity() const { return elasticityMatrix(material.young, material.poisson); }
	bool fixed = false;  // a fixed block has no unknowns: it never moves by the solve
	// A fixed block that a prescribed motion translates (World::addBaseMotion,
	// solver/BaseMotion.hpp): still no unknowns, its displacement over a step
	// is known. Set by World from its motions; not saved with the block.
	bool shaken = false;
	// A rigid block has 6 unknowns (translation, rotation): no strain, no
	// stress, no elastic term. Its strain unknowns and rates stay exactly zero
	// in the 12-vector layout, so contact code needs no special case.
	bool rigid = false;
	int unknowns() const { return fixed ? 0 : rigid ? kRigidBlockDofs : kBlockDofs; }
	std::vector<FixedPoint> fixedPoints;
	std::vector<PointLoad> loads;
	// Sum of |strain increment| since the YADE body's vertices were last
	// written; a sync rewrites them only when this exceeds round-off.
	double unsyncedStrain = 0;

	double density() const { return mass / volume; }  // current [kg/m^3]
	// Volume at creation [m^3] (the mass is conserved and the material's
	// density is the density at creation): the measure of the stored strain
	// energy and the elastic stiffness (BlockEquations.hpp, "Finite strain").
	double referenceVolume() const { return mass / material.density; }
	// Characteristic length: cube root of the volume at creation [m].
	double size = 0;

	// Concave blocks (World::addConcaveBlock; Wu et al. 2014, Section 4): a
	// concave block is a run of Blocks, one per convex part, at consecutive
	// indices. The first, its body, carries the block: its unknowns, velocity,
	// stress, strain, loads, fixed points, and the mass properties of the
	// whole block (volume, centroid, second moments, mass, size); its own
	// part's geometry (shape, vertices) is what the contact search sees of it.
	// The others carry only their part's geometry (and its own volume, centroid
	// and second moments) and move by the body's displacement function; their
	// mass, velocity, stress and strain stay zero, so a sum over all blocks
	// (the energy account) counts the block once. Parts never contact each
	// other; faces two parts share are internal (BlockGeometry::internalFaces).
	int body = -1;      // a part after the first: the index of its body; else -1
	int partCount = 1;  // the body of a concave block: its number of parts (itself included); else 1
	bool isPart() const { return body >= 0 || partCount > 1; }
};

}  // namespace dda
