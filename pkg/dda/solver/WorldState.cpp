// Saving and restoring a World (World::writeState / readState).
//
// Written, in container order: the step counters, time and next dt; Shi's w0
// as measured (it is measured once, from the geometry of the first step, and
// would differ if re-measured from moved blocks); the flush-joint faces; the
// last step's statistics; the collider (its name and, for MSC, its covers);
// every block (topology, current vertices, mass properties, rotation, 12
// rates, stress, strain, material, fixed and rigid flags, supports and
// loads); every sub-contact of the last step with its geometry, mechanics and history, in store order, and
// the pairs' entrance features. What is not written is rebuilt identically at
// the start of the next step: the contact store's history index (from the
// contacts), the coupled system, and the per-step work arrays.
#include "World.hpp"
#include "dda/collider/ColliderFactory.hpp"
#include "dda/core/StateStream.hpp"
#include "dda/geometry/MassProperties.hpp"

#include <algorithm>
#include <type_traits>

namespace dda {

namespace {

// Statistics are diagnostics: written raw, read back only when the layout of
// StepStatistics is the same (else left zero; nothing later depends on them).
static_assert(std::is_trivially_copyable_v<StepStatistics>);

void writeShape(StateWriter& out, const std::vector<Vector3>& vertices, const PolyhedronTopology& shape) {
	out.matrixVector(vertices);
	out.size(shape.faces.size());
	for (const auto& face : shape.faces) out.podVector(face);
	out.podVector(shape.edges);
	out.podVector(shape.edgeFaces);
}

ConvexPolyhedron readShape(StateReader& in) {
	ConvexPolyhedron shape;
	in.matrixVector(shape.vertices, "block vertices");
	const int nv = static_cast<int>(shape.vertices.size());
	if (nv < 4) in.fail("a block with " + std::to_string(nv) + " vertices");
	shape.faces.resize(in.size(8, "faces"));
	for (auto& face : shape.faces) {
		in.podVector(face, "face corners");
		for (int v : face)
			if (v < 0 || v >= nv) in.fail("face corner " + std::to_string(v) + " out of range");
	}
	in.podVector(shape.edges, "edges");
	in.podVector(shape.edgeFaces, "edge faces");
	const int nf = static_cast<int>(shape.faces.size());
	if (shape.edgeFaces.size() != shape.edges.size()) in.fail("edges and edge faces differ in number");
	// PolyhedronTopology::vertexCount counts on it (as buildConvexPolyhedron checks).
	if (shape.vertexCount() != nv) in.fail("a block's vertices, edges and faces fail Euler's formula V - E + F = 2");
	for (std::size_t e = 0; e < shape.edges.size(); ++e)
		for (int k = 0; k < 2; ++k)
			if (shape.edges[e][k] < 0 || shape.edges[e][k] >= nv || shape.edgeFaces[e][k] < 0 || shape.edgeFaces[e][k] >= nf)
				in.fail("edge " + std::to_string(e) + " has an index out of range");
	return shape;
}

void writeBlock(StateWriter& out, const Block& b) {
	writeShape(out, b.initialVertices, *b.shape);
	out.matrixVector(b.vertices);
	out.matrix(b.centroid);
	out.pod(b.volume);
	out.matrix(b.secondMoment);
	out.pod(b.mass);
	out.quaternion(b.rotation);
	out.matrix(b.velocity);
	out.matrix(b.stress);
	out.matrix(b.strain);
	const Material& m = b.material;
	for (double x : {m.density, m.young, m.poisson, m.frictionAngle, m.cohesion, m.tensileStrength}) out.pod(x);
	out.matrix(b.elasticity());  // kept in the format; read back only as a check
	out.pod(static_cast<std::uint8_t>(b.fixed));
	out.pod(static_cast<std::uint8_t>(b.rigid));
	out.size(b.fixedPoints.size());
	for (const FixedPoint& p : b.fixedPoints) {
		out.matrix(p.position);
		out.matrix(p.anchor);
		out.pod(p.stiffness);
	}
	out.size(b.loads.size());
	for (const PointLoad& l : b.loads) {
		out.matrix(l.position);
		out.matrix(l.force);
	}
	out.pod(b.unsyncedStrain);
	out.pod(b.size);
	out.pod(b.body);
	out.pod(b.partCount);
}

// The block's topology is its own; World::readState interns it.
Block readBlock(StateReader& in) {
	Block b;
	ConvexPolyhedron shape = readShape(in);
	b.initialCentroid = computeMassProperties(shape.vertices, shape.faces).centroid;
	b.initialVertices = std::move(shape.vertices);
	b.shape = std::make_shared<const PolyhedronTopology>(std::move(static_cast<PolyhedronTopology&>(shape)));
	in.matrixVector(b.vertices, "current vertices");
	if (b.vertices.size() != b.initialVertices.size()) in.fail("a block's current and initial vertices differ in number");
	in.matrix(b.centroid);
	in.pod(b.volume);
	in.matrix(b.secondMoment);
	in.pod(b.mass);
	in.quaternion(b.rotation);
	in.matrix(b.velocity);
	in.matrix(b.stress);
	in.matrix(b.strain);
	Material& m = b.material;
	for (double* x : {&m.density, &m.young, &m.poisson, &m.frictionAngle, &m.cohesion, &m.tensileStrength}) in.pod(*x);
	// The block holds no elasticity matrix (Block::elasticity computes it from
	// the material); the one saved must be that one, or the restored block
	// would not continue as the saved one.
	Matrix6 elasticity;
	in.matrix(elasticity);
	if (elasticity != b.elasticity()) in.fail("a block's elasticity matrix does not follow from its young and poisson");
	b.fixed = in.pod<std::uint8_t>() != 0;
	b.rigid = in.pod<std::uint8_t>() != 0;
	b.fixedPoints.resize(in.size(7 * sizeof(double), "fixed points"));
	for (FixedPoint& p : b.fixedPoints) {
		in.matrix(p.position);
		in.matrix(p.anchor);
		in.pod(p.stiffness);
	}
	b.loads.resize(in.size(6 * sizeof(double), "point loads"));
	for (PointLoad& l : b.loads) {
		in.matrix(l.position);
		in.matrix(l.force);
	}
	in.pod(b.unsyncedStrain);
	in.pod(b.size);
	in.pod(b.body);
	in.pod(b.partCount);
	return b;
}

void writeHistory(StateWriter& out, const ContactHistory& h) {
	out.pod(h.state);
	out.matrix(h.anchorI);
	out.matrix(h.anchorJ);
	out.matrix(h.slidingDirection);
	out.pod(h.normalForce);
	out.pod(static_cast<std::uint8_t>(h.bonded));
	out.matrix(h.shearForce);
}

void readHistory(StateReader& in, ContactHistory& h) {
	const auto state = in.pod<std::uint8_t>();
	if (state > static_cast<std::uint8_t>(ContactState::Locked)) in.fail("contact state " + std::to_string(state));
	h.state = static_cast<ContactState>(state);
	in.matrix(h.anchorI);
	in.matrix(h.anchorJ);
	in.matrix(h.slidingDirection);
	in.pod(h.normalForce);
	h.bonded = in.pod<std::uint8_t>() != 0;
	in.matrix(h.shearForce);
}

ContactKind readKind(StateReader& in) {
	const int kind = in.pod<int>();
	if (kind != static_cast<int>(ContactKind::VertexFace) && kind != static_cast<int>(ContactKind::EdgeEdge))
		in.fail("contact kind " + std::to_string(kind));
	return static_cast<ContactKind>(kind);
}

void writeContact(StateWriter& out, const Contact& c) {
	out.pod(c.key.blockI);
	out.pod(c.key.blockJ);
	out.pod(static_cast<int>(c.key.kind));
	out.pod(c.key.feature1);
	out.pod(c.key.feature2);
	out.pod(static_cast<int>(c.pairType));
	const SubContact& g = c.geometry;
	out.pod(static_cast<int>(g.kind));
	out.pod(static_cast<std::uint8_t>(g.firstIsA));
	out.pod(g.feature1);
	out.pod(g.feature2);
	out.pod(static_cast<int>(g.stencil.kind));
	for (const Vector3& p : g.stencil.points) out.matrix(p);
	out.pod(g.stencil.sigma);
	out.pod(g.gap);
	out.matrix(g.normal);
	out.matrix(g.pointI);
	out.matrix(g.pointJ);
	writeHistory(out, c.history);
	writeHistory(out, c.trial);
	const LinearizedDistance& n = c.normal;
	out.pod(static_cast<std::uint8_t>(n.valid));
	out.pod(n.d0);
	out.matrix(n.ei);
	out.matrix(n.ej);
	out.pod(n.delta);
	out.pod(n.area);
	for (double x : {c.normalStiffness, c.shearStiffness, c.frictionTangent, c.area, c.cohesionForce, c.tensileForce})
		out.pod(x);
	out.pod(static_cast<std::uint8_t>(c.isNew));
	out.matrix(c.point);
}

Contact readContact(StateReader& in, int blocks) {
	Contact c;
	c.key.blockI = in.index(blocks, "contact block");
	c.key.blockJ = in.index(blocks, "contact block");
	c.key.kind = readKind(in);
	in.pod(c.key.feature1);
	in.pod(c.key.feature2);
	const int type = in.pod<int>();
	if (type < 0 || type > static_cast<int>(ContactType::FaceFace)) in.fail("contact type " + std::to_string(type));
	c.pairType = static_cast<ContactType>(type);
	SubContact& g = c.geometry;
	g.kind = readKind(in);
	g.firstIsA = in.pod<std::uint8_t>() != 0;
	in.pod(g.feature1);
	in.pod(g.feature2);
	g.stencil.kind = readKind(in);
	for (Vector3& p : g.stencil.points) in.matrix(p);
	in.pod(g.stencil.sigma);
	in.pod(g.gap);
	in.matrix(g.normal);
	in.matrix(g.pointI);
	in.matrix(g.pointJ);
	readHistory(in, c.history);
	readHistory(in, c.trial);
	LinearizedDistance& n = c.normal;
	n.valid = in.pod<std::uint8_t>() != 0;
	in.pod(n.d0);
	in.matrix(n.ei);
	in.matrix(n.ej);
	in.pod(n.delta);
	in.pod(n.area);
	for (double* x : {&c.normalStiffness, &c.shearStiffness, &c.frictionTangent, &c.area, &c.cohesionForce, &c.tensileForce})
		in.pod(*x);
	c.isNew = in.pod<std::uint8_t>() != 0;
	in.matrix(c.point);
	return c;
}

std::unique_ptr<Collider> colliderNamed(const std::string& name, StateReader& in) {
	if (std::unique_ptr<Collider> collider = makeCollider(name)) return collider;
	in.fail("unknown collider '" + name + "'");
}

}  // namespace

void World::writeState(StateWriter& out) const {
	out.tag("WRLD");
	out.pod(time_);
	out.pod(steps_);
	timeStep_.writeState(out);  // next dt, open-close failures, displacement-limit misses
	out.pod(motionHalfSize_);
	out.pod(motionSizedBlocks_);
	detection_.writeState(out);  // the flush-joint faces
	out.size(sizeof(StepStatistics));
	out.pod(stats_);
	out.tag("ENRG");
	for (double x : {energy_.kinetic, energy_.gravity, energy_.strain, energy_.contact, energy_.friction,
	                 energy_.damping, energy_.loads, energy_.contactChanges})
		out.pod(x);
	out.matrix(gravity_);

	out.tag("BLKS");
	out.size(blocks_.size());
	for (const Block& b : blocks_) writeBlock(out, b);

	out.tag("COLL");
	out.string(collider_->name());
	collider_->writeState(out);

	out.tag("CNTS");
	const std::vector<Contact>& contacts = store_.contacts();
	out.size(contacts.size());
	for (const Contact& c : contacts) writeContact(out, c);
	// Entrances by key order, so equal states give equal bytes.
	std::vector<std::pair<std::uint64_t, EntranceFeature>> entrances(store_.entrances().begin(), store_.entrances().end());
	std::sort(entrances.begin(), entrances.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
	out.size(entrances.size());
	for (const auto& [key, e] : entrances) {
		out.pod(key);
		out.pod(static_cast<int>(e.kind));
		out.pod(e.feature);
		out.pod(e.other);
	}
	writeBaseMotions(out);
	out.tag("END.");
}

void World::readState(StateReader& in) {
	World w;
	in.tag("WRLD");
	in.pod(w.time_);
	in.pod(w.steps_);
	w.timeStep_.readState(in);
	in.pod(w.motionHalfSize_);
	in.pod(w.motionSizedBlocks_);
	w.detection_.readState(in);
	const std::size_t statsBytes = in.size(1, "statistics bytes");
	if (statsBytes == sizeof(StepStatistics)) {
		in.pod(w.stats_);
	} else {
		for (std::size_t k = 0; k < statsBytes; ++k) in.pod<char>();
	}
	in.tag("ENRG");
	for (double* x : {&w.energy_.kinetic, &w.energy_.gravity, &w.energy_.strain, &w.energy_.contact,
	                  &w.energy_.friction, &w.energy_.damping, &w.energy_.loads, &w.energy_.contactChanges})
		in.pod(*x);
	in.matrix(w.gravity_);

	in.tag("BLKS");
	w.blocks_.resize(in.size(64, "blocks"));
	for (Block& b : w.blocks_) {
		b = readBlock(in);
		b.shape = w.topologies_.intern(std::move(b.shape));
	}
	const int n = w.blockCount();
	// Concave blocks: each body followed by its other parts, which refer to it.
	for (int b = 0; b < n; ++b) {
		const Block& block = w.blocks_[b];
		if (block.body >= 0 ? block.partCount != 1 || block.body >= b || w.blocks_[block.body].partCount <= b - block.body
		                    : block.partCount < 1 || b + block.partCount > n)
			in.fail("block " + std::to_string(b) + " has inconsistent concave-block parts");
		for (int p = 1; p < block.partCount; ++p)
			if (w.blocks_[b + p].body != b) in.fail("part " + std::to_string(b + p) + " does not refer to its body");
	}
	const std::vector<std::vector<char>>& internalFaces = w.detection_.internalFaces();
	if (internalFaces.size() > w.blocks_.size()) in.fail("more internal-face lists than blocks");
	for (std::size_t b = 0; b < internalFaces.size(); ++b)
		if (!internalFaces[b].empty() && internalFaces[b].size() != w.blocks_[b].shape->faces.size())
			in.fail("internal faces of block " + std::to_string(b) + " do not match its faces");

	in.tag("COLL");
	std::string name;
	in.string(name);
	w.collider_ = colliderNamed(name, in);
	w.collider_->readState(in, w.blocks_);

	in.tag("CNTS");
	std::vector<Contact> contacts(in.size(64, "contacts"));
	for (Contact& c : contacts) {
		c = readContact(in, n);
		c.bodyI = w.bodyOf(c.key.blockI);
		c.bodyJ = w.bodyOf(c.key.blockJ);
	}
	std::unordered_map<std::uint64_t, EntranceFeature> entrances;
	const std::size_t entranceCount = in.size(8 + 3 * sizeof(int), "entrance features");
	for (std::size_t k = 0; k < entranceCount; ++k) {
		const auto key = in.pod<std::uint64_t>();
		EntranceFeature e;
		const int kind = in.pod<int>();
		if (kind < EntranceFeature::None || kind > EntranceFeature::EdgePair) in.fail("entrance kind " + std::to_string(kind));
		e.kind = static_cast<EntranceFeature::Kind>(kind);
		in.pod(e.feature);
		in.pod(e.other);
		entrances.emplace(key, e);
	}
	w.store_.restore(std::move(contacts), std::move(entrances));
	w.readBaseMotions(in);
	in.tag("END.");
	*this = std::move(w);
}

}  // namespace dda
