// Fuzz target for the geometry and contact kernels of the DDA core
// (libFuzzer's entry point, LLVMFuzzerTestOneInput; driver.cpp feeds it
// without clang).
//
// The input bytes are read as a recipe, so every byte string is a valid test
// and the fuzzer spends its time on geometry, not on parsing. Byte 0 picks
// the mode:
//   0  buildConvexPolyhedron on a point set from one of ten families: raw
//      doubles (NaN, inf, denormals), grid points (coplanar, collinear,
//      on-hull-but-not-corner), coplanar, collinear, duplicated, a box with
//      one corner pushed by 10^-k, regular solids, slabs 10^-k thin, points on
//      a sphere, near-coincident points; scaled by 10^-15 .. 10^15 and moved
//      up to 10^14 from the origin;
//   1  detectPairContacts and the contact equations (prepareContact,
//      contactTerms for each state, evaluateContact, finishContact) on two
//      valid blocks placed: at random, corner on corner, edge on edge
//      (crossing or parallel), face on face (coplanar, turned, offset), one
//      inside the other, identical, or at exactly d0 along a face normal;
//   2  World::step on 2 to 4 such blocks (random fixed flags, collider, MSC
//      cover, dt, gravity), 1 to 3 steps.
// Findings (abort, so that libFuzzer and the driver stop with the input):
//   - any exception other than dda::InputError from buildConvexPolyhedron
//     (its internal errors are std::logic_error), or any exception at all
//     from the narrow phase and contact equations on valid blocks;
//   - a valid polyhedron that breaks its own contract (Euler, faces of >= 3
//     distinct corners, each edge in two faces, finite positive volume);
//   - NaN or inf in any output: polyhedron, mass properties, separation,
//     normals, gaps, points, stencils, linearisation, 24x24 terms, states;
//   - World::step: an exception other than InputError or the core's own
//     runtime_error messages (non-finite displacement, Cholesky failure),
//     or a non-finite block state after a step that returned.
// Units: metres (the scale factor sweeps 30 decades on purpose).
#include "dda/collider/MSCCollider.hpp"
#include "dda/contact/Linearization.hpp"
#include "dda/contact/PairDetection.hpp"
#include "dda/geometry/ConvexPolyhedron.hpp"
#include "dda/geometry/MassProperties.hpp"
#include "dda/solver/ContactEquations.hpp"
#include "dda/solver/World.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "fuzz_kernels.hpp"

using namespace dda;

namespace {

FuzzCounters counters;

// ------------------------------------------------------------------ input

// Reads numbers from the fuzzer's bytes; past the end it reads zeros, so
// short inputs are valid too.
class Recipe {
public:
	Recipe(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
	std::uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }
	std::uint32_t u32() {
		std::uint32_t v = 0;
		for (int k = 0; k < 4; ++k) v = (v << 8) | byte();
		return v;
	}
	int below(int n) { return n <= 1 ? 0 : static_cast<int>(byte() % n); }
	bool coin() { return byte() & 1; }
	double unit() { return u32() / 4294967296.0; }    // [0, 1)
	double symmetric() { return 2 * unit() - 1; }      // [-1, 1)
	double raw() {                                      // any double, NaN and inf included
		std::uint64_t bits = (static_cast<std::uint64_t>(u32()) << 32) | u32();
		double x;
		std::memcpy(&x, &bits, sizeof x);
		return x;
	}
	double power10(int lo, int hi) { return std::pow(10.0, lo + below(hi - lo + 1)); }
	Vector3 direction() {
		Vector3 v(symmetric(), symmetric(), symmetric());
		return v.norm() > 1e-6 ? v.normalized() : Vector3::UnitZ();
	}
	Eigen::Matrix3d rotation() {
		switch (below(4)) {
		case 0: return Eigen::Matrix3d::Identity();
		case 1: {  // a quarter turn about an axis: exact
			Eigen::Matrix3d r = Eigen::Matrix3d::Zero();
			const int axis = below(3);
			r(axis, axis) = 1;
			r((axis + 1) % 3, (axis + 2) % 3) = -1;
			r((axis + 2) % 3, (axis + 1) % 3) = 1;
			return r;
		}
		case 2: return Eigen::AngleAxisd(power10(-12, -1) * (coin() ? 1 : -1), direction()).toRotationMatrix();
		default: return Eigen::AngleAxisd(M_PI * symmetric(), direction()).toRotationMatrix();
		}
	}

private:
	const std::uint8_t* data_;
	std::size_t size_, pos_ = 0;
};

// ------------------------------------------------------------------ failures

// What the current input built, printed with a finding (exact hex floats).
std::string context;

std::string describe(const char* name, const std::vector<Vector3>& points) {
	std::string out = std::string(name) + " = {";
	char buffer[128];
	for (const Vector3& p : points) {
		std::snprintf(buffer, sizeof buffer, "{%a, %a, %a}, ", p.x(), p.y(), p.z());
		out += buffer;
	}
	return out + "}\n";
}

[[noreturn]] void fail(const std::string& what) {
	std::fprintf(stderr, "\nFUZZ FINDING: %s\n%s", what.c_str(), context.c_str());
	std::fflush(stderr);
	std::abort();
}

void requireFinite(double x, const char* what) {
	if (!std::isfinite(x)) fail(std::string("non-finite ") + what);
}
template <class Derived>
void requireFinite(const Eigen::MatrixBase<Derived>& m, const char* what) {
	if (!m.allFinite()) fail(std::string("non-finite ") + what);
}
void requireFinite(const std::vector<Vector3>& points, const char* what) {
	for (const Vector3& p : points) requireFinite(p, what);
}

// ------------------------------------------------------------------ shapes

std::vector<Vector3> box(const Vector3& half) {
	std::vector<Vector3> p;
	for (int i = 0; i < 8; ++i)
		p.emplace_back(i & 1 ? half.x() : -half.x(), i & 2 ? half.y() : -half.y(), i & 4 ? half.z() : -half.z());
	return p;
}

// Convex solids every point of which is a corner.
std::vector<Vector3> regularSolid(Recipe& in) {
	switch (in.below(6)) {
	case 0: return box(Vector3(0.5, 0.5, 0.5));
	case 1: return {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
	case 2: {  // triangular prism
		const double h = 0.2 + in.unit();
		return {{0, 0, 0}, {1, 0, 0}, {0.3, 0.9, 0}, {0, 0, h}, {1, 0, h}, {0.3, 0.9, h}};
	}
	case 3: return {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};  // octahedron
	case 4: {  // slender box, up to 100:1
		const double length = 1 + 99 * in.unit();
		return box(Vector3(0.5 * length, 0.5, 0.5));
	}
	default: {  // random box
		return box(Vector3(0.05 + in.unit(), 0.05 + in.unit(), 0.05 + in.unit()));
	}
	}
}

std::vector<Vector3> spherePoints(Recipe& in, int n, double noise) {
	std::vector<Vector3> p;
	for (int k = 0; k < n; ++k) p.push_back(in.direction() * (1 + noise * in.symmetric()));
	return p;
}

// A point set of family 0..9 (see the header comment), before scaling.
std::vector<Vector3> pointSet(Recipe& in, int family) {
	std::vector<Vector3> p;
	switch (family) {
	case 0: {  // raw doubles
		const int n = in.below(16);
		for (int k = 0; k < n; ++k) p.emplace_back(in.raw(), in.raw(), in.raw());
		return p;
	}
	case 1: {  // grid points: coplanar, collinear and on-hull-not-corner galore
		const int n = 4 + in.below(14), levels = 2 + in.below(3);
		for (int k = 0; k < n; ++k) p.emplace_back(in.below(levels), in.below(levels), in.below(levels));
		return p;
	}
	case 2: {  // coplanar, plus maybe one point 10^-k off the plane
		const Vector3 n = in.direction(), u = n.unitOrthogonal(), v = n.cross(u);
		const int count = 3 + in.below(8);
		for (int k = 0; k < count; ++k) p.push_back(in.symmetric() * u + in.symmetric() * v);
		if (in.coin()) p.push_back(0.1 * u + in.power10(-17, -1) * n);
		return p;
	}
	case 3: {  // collinear, plus zero to two points off the line
		const Vector3 d = in.direction();
		const int count = 2 + in.below(6), off = in.below(3);
		for (int k = 0; k < count; ++k) p.push_back(in.symmetric() * d);
		for (int k = 0; k < off; ++k) p.push_back(in.power10(-16, 0) * in.direction());
		return p;
	}
	case 4: {  // a solid with one point duplicated, exactly or within 10^-k
		p = regularSolid(in);
		const Vector3 copy = p[in.below(static_cast<int>(p.size()))];
		p.insert(p.begin() + in.below(static_cast<int>(p.size()) + 1),
		         in.coin() ? copy : Vector3(copy + in.power10(-17, -6) * in.direction()));
		return p;
	}
	case 5: {  // box with one corner pushed by 10^-k: nearly coplanar faces
		p = box(Vector3(0.5, 0.5, 0.5));
		p[in.below(8)] += in.power10(-16, -2) * in.direction();
		return p;
	}
	case 6: return regularSolid(in);
	case 7: {  // slab 10^-k thin
		const double t = in.power10(-16, -1);
		return box(Vector3(0.5, 0.5, 0.5 * t));
	}
	case 8: return spherePoints(in, 4 + in.below(36), in.coin() ? 0.0 : in.power10(-16, -3));
	default: {  // a tetrahedron and a point 10^-k from one of its corners or edges
		p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
		const Vector3 a = p[in.below(4)], b = p[in.below(4)];
		p.push_back(0.5 * (a + b) + in.power10(-16, -4) * in.direction());
		return p;
	}
	}
}

// Scales by 10^s, turns and moves a point set (family 0, raw doubles, is left alone).
void transform(Recipe& in, std::vector<Vector3>& p) {
	const double scale = in.power10(-15, 15);
	const Eigen::Matrix3d r = in.rotation();
	const Vector3 offset = in.coin() ? Vector3::Zero() : Vector3(in.power10(-5, 14) * in.direction());
	for (Vector3& x : p) x = r * (scale * x) + offset;
}

// ------------------------------------------------------------------ mode 0

void checkPolyhedron(const ConvexPolyhedron& shape, std::size_t pointCount) {
	if (shape.vertices.size() != pointCount) fail("polyhedron lost or gained vertices");
	requireFinite(shape.vertices, "polyhedron vertex");
	const long v = static_cast<long>(shape.vertices.size()), e = static_cast<long>(shape.edges.size()),
	           f = static_cast<long>(shape.faces.size());
	if (v - e + f != 2) fail("Euler's formula fails on a returned polyhedron");
	if (shape.edgeFaces.size() != shape.edges.size()) fail("edgeFaces and edges differ in size");
	for (const auto& face : shape.faces) {
		if (face.size() < 3) fail("face with fewer than 3 corners");
		std::set<int> distinct(face.begin(), face.end());
		if (distinct.size() != face.size()) fail("face repeats a corner");
		for (int k : face)
			if (k < 0 || k >= v) fail("face corner index out of range");
		requireFinite(faceNormal(shape.vertices, face), "face normal");
		for (int k : chooseFaceCorners(shape.vertices, face))
			if (k < 0 || k >= v) fail("chooseFaceCorners index out of range");
	}
	for (std::size_t k = 0; k < shape.edges.size(); ++k) {
		const auto& ef = shape.edgeFaces[k];
		if (ef[0] < 0 || ef[1] < 0 || ef[0] >= f || ef[1] >= f || ef[0] == ef[1]) fail("edge without two faces");
	}
	const MassProperties m = computeMassProperties(shape.vertices, shape.faces);
	requireFinite(m.volume, "volume");
	requireFinite(m.centroid, "centroid");
	requireFinite(m.secondMoment, "second moment");
	if (!(m.volume > 0)) fail("a returned polyhedron has volume <= 0");
}

void fuzzPolyhedron(Recipe& in) {
	const int family = in.below(10);
	std::vector<Vector3> points = pointSet(in, family);
	if (family != 0) transform(in, points);
	context = describe("points", points);
	try {
		const ConvexPolyhedron shape = buildConvexPolyhedron(points);
		++counters.polyhedraBuilt;
		checkPolyhedron(shape, points.size());
	} catch (const InputError&) {
		++counters.polyhedraRejected;
	}
}

// ------------------------------------------------------------------ placement of two blocks

// Corners of a valid block (a regular solid, turned, at a scale 10^-3 .. 10^3).
std::vector<Vector3> validBlock(Recipe& in, double& size) {
	std::vector<Vector3> p = regularSolid(in);
	size = in.power10(-3, 3);
	const Eigen::Matrix3d r = in.rotation();
	for (Vector3& x : p) x = r * (size * x);
	return p;
}

void translate(std::vector<Vector3>& p, const Vector3& by) {
	for (Vector3& x : p) x += by;
}

// The outward unit normal and a corner of face `f` of the hull of p.
struct FaceRef {
	Vector3 normal, corner;
	std::vector<int> corners;
};
FaceRef faceOf(const std::vector<Vector3>& p, Recipe& in) {
	const ConvexPolyhedron shape = buildConvexPolyhedron(p);
	const auto& face = shape.faces[in.below(static_cast<int>(shape.faces.size()))];
	return {faceNormal(shape.vertices, face), shape.vertices[face[0]], face};
}
std::array<Vector3, 2> edgeOf(const std::vector<Vector3>& p, Recipe& in) {
	const ConvexPolyhedron shape = buildConvexPolyhedron(p);
	const auto& e = shape.edges[in.below(static_cast<int>(shape.edges.size()))];
	return {shape.vertices[e[0]], shape.vertices[e[1]]};
}

// Places block b against block a; returns a contact distance to use [m].
double place(Recipe& in, const std::vector<Vector3>& a, std::vector<Vector3>& b, double size) {
	double d0 = in.coin() ? 0.0 : size * in.power10(-9, -1);
	switch (in.below(8)) {
	case 0:  // at random, near
		translate(b, size * 2 * Vector3(in.symmetric(), in.symmetric(), in.symmetric()));
		break;
	case 1: {  // corner on corner, exactly or 10^-k apart
		const Vector3 va = a[in.below(static_cast<int>(a.size()))], vb = b[in.below(static_cast<int>(b.size()))];
		translate(b, va - vb + (in.coin() ? Vector3::Zero() : Vector3(size * in.power10(-15, -2) * in.direction())));
		break;
	}
	case 2: {  // edge on edge: midpoints together, B's edge turned to cross or lie along A's
		const auto ea = edgeOf(a, in);
		const auto eb = edgeOf(b, in);
		if (in.coin()) {  // parallel: turn B so its edge lies along A's
			const Vector3 da = (ea[1] - ea[0]).normalized(), db = (eb[1] - eb[0]).normalized();
			const Eigen::Matrix3d r = Eigen::Quaterniond::FromTwoVectors(db, da).toRotationMatrix();
			const Vector3 mid = 0.5 * (eb[0] + eb[1]);
			for (Vector3& x : b) x = mid + r * (x - mid);
		}
		const auto eb2 = edgeOf(b, in);
		translate(b, 0.5 * (ea[0] + ea[1]) - 0.5 * (eb2[0] + eb2[1]));
		break;
	}
	case 3: {  // face on face: B's face turned against A's, coplanar, offset in the plane
		const FaceRef fa = faceOf(a, in);
		const FaceRef fb = faceOf(b, in);
		const Eigen::Matrix3d r = Eigen::Quaterniond::FromTwoVectors(fb.normal, -fa.normal).toRotationMatrix();
		for (Vector3& x : b) x = r * x;
		const Vector3 corner = r * fb.corner;
		const Vector3 u = fa.normal.unitOrthogonal(), v = fa.normal.cross(u);
		const Vector3 shift = in.coin() ? Vector3::Zero() : Vector3(size * (in.symmetric() * u + in.symmetric() * v));
		translate(b, fa.corner - corner + shift);
		break;
	}
	case 4: {  // exactly d0 (or d0 +- 10^-k) apart along a face normal of A
		const FaceRef fa = faceOf(a, in);
		double lowest = INFINITY;
		for (const Vector3& x : b) lowest = std::min(lowest, fa.normal.dot(x - fa.corner));
		const double gap = d0 + (in.coin() ? 0.0 : size * in.power10(-15, -3) * (in.coin() ? 1 : -1));
		translate(b, (gap - lowest) * fa.normal);
		break;
	}
	case 5:  // deep: B's centre at a random point of A (one inside the other, or crossing)
		translate(b, a[in.below(static_cast<int>(a.size()))] * in.unit());
		break;
	case 6:  // identical blocks, or shifted by 10^-k
		b = a;
		if (in.coin()) translate(b, size * in.power10(-15, -1) * in.direction());
		break;
	default:  // far apart, beyond any d0
		translate(b, Vector3(1e3 * size, 0, 0));
		break;
	}
	return d0;
}

// ------------------------------------------------------------------ mode 1

void checkContact(const Contact& c) {
	requireFinite(c.normal.d0, "linearised gap");
	requireFinite(c.normal.ei, "gap gradient e_i");
	requireFinite(c.normal.ej, "gap gradient e_j");
	requireFinite(c.normalStiffness, "normal stiffness");
	requireFinite(c.shearStiffness, "shear stiffness");
	requireFinite(c.frictionTangent, "friction tangent");
	requireFinite(c.trial.normalForce, "normal force");
	requireFinite(c.trial.shearForce, "shear force");
	requireFinite(c.trial.anchorI, "anchor I");
	requireFinite(c.trial.anchorJ, "anchor J");
	requireFinite(c.trial.slidingDirection, "sliding direction");
}

void checkPair(const PairContacts& pair) {
	requireFinite(pair.separation, "separation");
	requireFinite(pair.normal, "entrance normal");
	if (std::abs(pair.normal.norm() - 1) > 1e-6) fail("entrance normal is not a unit vector");
	for (const SubContact& s : pair.contacts) {
		requireFinite(s.gap, "sub-contact gap");
		requireFinite(s.normal, "sub-contact normal");
		requireFinite(s.pointI, "sub-contact point I");
		requireFinite(s.pointJ, "sub-contact point J");
		for (const Vector3& q : s.stencil.points) requireFinite(q, "stencil point");
		if (std::abs(s.normal.norm() - 1) > 1e-6) fail("sub-contact normal is not a unit vector");
	}
}

// The contact equations of every sub-contact, in every state, for a random
// small motion of the two blocks.
void exerciseEquations(Recipe& in, const PairContacts& pair, const Block& a, const Block& b) {
	IntegratorSettings settings;
	for (const SubContact& sub : pair.contacts) {
		const Block& bi = sub.firstIsA ? a : b;
		const Block& bj = sub.firstIsA ? b : a;
		Contact c;
		c.key = ContactKey{sub.firstIsA ? 0 : 1, sub.firstIsA ? 1 : 0, sub.kind, sub.feature1, sub.feature2};
		c.pairType = pair.type;
		c.geometry = sub;
		prepareContact(c, bi, bj, settings);
		startTrial(c, in.coin());
		checkContact(c);
		Vector12 Di = Vector12::Zero(), Dj = Vector12::Zero();
		const double scale = (bi.size + bj.size) * in.power10(-12, -2);
		for (int k = 0; k < 12; ++k) {
			Di(k) = scale * in.symmetric() * (k < 3 ? 1.0 : 1.0 / std::max(bi.size, 1e-300));
			Dj(k) = scale * in.symmetric() * (k < 3 ? 1.0 : 1.0 / std::max(bj.size, 1e-300));
		}
		if (bi.fixed) Di.setZero();
		if (bj.fixed) Dj.setZero();
		for (ContactState state : {ContactState::Locked, ContactState::Sliding, ContactState::Open}) {
			c.trial.state = state;
			c.trial.anchorI = sub.pointI;
			c.trial.anchorJ = sub.pointJ;
			c.trial.slidingDirection = in.coin() ? Vector3::Zero() : in.direction();
			c.trial.normalForce = in.coin() ? 0.0 : c.normalStiffness * scale * in.unit();
			c.stretch = in.coin() ? Vector3::Zero() : Vector3(scale * in.unit() * in.direction());
			c.slipLimit = in.coin() ? 0.0 : c.normalStiffness * scale * in.unit();
			Matrix24 stiffness;
			Vector24 force;
			if (contactTerms(c, bi, bj, stiffness, force)) {
				requireFinite(stiffness, "contact stiffness");
				requireFinite(force, "contact force");
			}
			requireFinite(contactGap(c, Di, Dj), "contact gap");
			evaluateContact(c, bi, bj, Di, Dj);
			if (in.coin()) updateFrictionLimit(c, in.coin());
			checkContact(c);
			finishContact(c, bi, bj, Di, Dj);
			checkContact(c);
		}
	}
}

void fuzzPair(Recipe& in) {
	double sizeA = 1, sizeB = 1;
	std::vector<Vector3> a = validBlock(in, sizeA), b = validBlock(in, sizeB);
	const double d0 = place(in, a, b, std::min(sizeA, sizeB));
	if (in.coin()) {  // far from the origin: round-off in the placement
		const Vector3 far = in.power10(0, 8) * in.direction();
		translate(a, far);
		translate(b, far);
	}
	context = describe("blockA", a) + describe("blockB", b);
	World world;
	Material material;
	try {
		world.addBlock(a, material, in.coin());
		world.addBlock(b, material, false);
	} catch (const InputError&) {
		++counters.polyhedraRejected;  // far from the origin a block may round to too flat
		return;
	}
	const Block& A = world.block(0);
	const Block& B = world.block(1);
	// The integrator's settings, at the smallest or the largest parallel-edge angle.
	DetectionSettings settings = pairDetectionSettings(boundingDiagonal(A), boundingDiagonal(B), d0, 0.0);
	if (in.coin()) settings.angleTolerance = 0.05;
	const BlockGeometry ga{A.shape.get(), &A.vertices, A.centroid};
	const BlockGeometry gb{B.shape.get(), &B.vertices, B.centroid};
	EntranceFeature previous;
	for (int round = 0; round < 2; ++round) {
		std::optional<PairContacts> result;
		try {
			result = round == 0 ? detectPairContacts(ga, gb, settings, previous) : detectPairContacts(gb, ga, settings);
		} catch (const std::exception& e) {
			fail(std::string("detectPairContacts threw on valid blocks: ") + e.what());
		}
		if (!result) continue;
		++counters.pairsInContact;
		counters.subContacts += static_cast<long>(result->contacts.size());
		checkPair(*result);
		previous = result->entrance;
		try {
			exerciseEquations(in, *result, round == 0 ? A : B, round == 0 ? B : A);
		} catch (const std::exception& e) {
			fail(std::string("the contact equations threw: ") + e.what());
		}
	}
}

// ------------------------------------------------------------------ mode 2

void checkWorld(const World& world) {
	for (int i = 0; i < world.blockCount(); ++i) {
		const Block& b = world.block(i);
		requireFinite(b.vertices, "block vertex after a step");
		requireFinite(b.velocity, "block velocity after a step");
		requireFinite(b.stress, "block stress after a step");
		requireFinite(b.centroid, "block centroid after a step");
	}
	for (const Contact& c : world.contacts()) {
		requireFinite(c.history.normalForce, "contact normal force after a step");
		requireFinite(c.history.shearForce, "contact shear force after a step");
		requireFinite(c.point, "contact point after a step");
	}
	requireFinite(world.lastStep().maxPenetration, "maxPenetration");
}

void fuzzWorld(Recipe& in) {
	World world;
	Material material;
	material.young = in.power10(5, 11);
	material.poisson = 0.49 * in.symmetric();
	material.frictionAngle = in.coin() ? 0.0 : 1.5 * in.unit();
	material.cohesion = in.coin() ? 0.0 : in.power10(3, 7);
	material.tensileStrength = in.coin() ? 0.0 : in.power10(3, 7);
	const int n = 2 + in.below(3);
	double size = 1;
	std::vector<Vector3> first = validBlock(in, size);
	context = describe("block", first);
	try {
		world.addBlock(first, material, in.coin());
		for (int k = 1; k < n; ++k) {
			double other = 1;
			std::vector<Vector3> b = validBlock(in, other);
			place(in, world.block(in.below(k)).vertices, b, std::min(size, other));
			context += describe("block", b);
			world.addBlock(b, material, in.below(4) == 0);
		}
	} catch (const InputError&) {
		++counters.polyhedraRejected;
		return;
	}
	switch (in.below(5)) {
	case 0: world.setCollider(std::make_unique<AllPairsCollider>()); break;
	case 1: world.setCollider(std::make_unique<NBSCollider>()); break;
	case 2: {
		auto msc = std::make_unique<MSCCollider>();
		msc->setCover(in.coin() ? 0.0 : size * in.power10(-2, 1), 1 + in.below(MSCCollider::kMaxSegments));
		world.setCollider(std::move(msc));
		break;
	}
	default: break;  // DESS
	}
	IntegratorSettings settings;
	settings.maxTimeStep = in.power10(-6, -1);
	settings.gravity = in.coin() ? Vector3(0, 0, -9.81) : Vector3(in.power10(-2, 3) * in.direction());
	settings.velocityRatio = in.coin() ? 1.0 : in.unit();
	settings.maxDisplacement = in.coin() ? 0.0 : size * in.power10(-4, -1);
	settings.maxStepCuts = in.below(8);
	settings.maxOpenCloseIterations = 1 + in.below(20);
	settings.threads = 1;
	const int steps = 1 + in.below(3);
	for (int s = 0; s < steps; ++s) {
		try {
			world.step(settings);
		} catch (const InputError&) {
			++counters.stepsRefused;
			return;
		} catch (const std::runtime_error& e) {
			// The core's own guards: a clear error, not a crash. Counted.
			const std::string what = e.what();
			if (what.find("non-finite displacement") == std::string::npos &&
			    what.find("not positive definite") == std::string::npos &&
			    what.find("of its volume") == std::string::npos)  // a step that would turn a block inside out
				fail("World::step threw an unexpected runtime_error: " + what);
			if (std::getenv("DDA_FUZZ_STRICT")) fail("World::step refused (DDA_FUZZ_STRICT): " + what);
			++counters.stepsRefused;
			return;
		} catch (const std::exception& e) {
			fail(std::string("World::step threw: ") + e.what());
		}
		++counters.steps;
		checkWorld(world);
	}
}

}  // namespace

const FuzzCounters& fuzzCounters() { return counters; }

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
	Recipe in(data, size);
	++counters.inputs;
	context.clear();
	try {
		switch (in.below(3)) {
		case 0: fuzzPolyhedron(in); break;
		case 1: fuzzPair(in); break;
		default: fuzzWorld(in); break;
		}
	} catch (const std::exception& e) {
		fail(std::string("uncaught exception: ") + e.what());
	}
	return 0;
}
