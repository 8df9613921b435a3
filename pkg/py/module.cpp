// yade_dda._core: the Boost.Python face of the DDA core.
//
// Eigen::Vector3d, Matrix3d and Quaterniond cross the boundary as YADE's own
// Vector3, Matrix3 and Quaternion: YADE's minieigen registers those converters
// in Boost.Python's shared registry, so yade must be imported first (the
// yade_dda package does that). Core exceptions become Python exceptions:
// dda::InputError (a std::invalid_argument) -> ValueError, std::out_of_range ->
// IndexError, anything else -> RuntimeError.
#include "SceneLink.hpp"
#include "dda/geometry/ConvexDecomposition.hpp"
#include "dda/geometry/ConvexParts.hpp"
#include "YadeSync.hpp"
#include "dda/collider/ColliderFactory.hpp"
#include "dda/solver/InitialOverlaps.hpp"

#include <boost/python.hpp>

namespace py = boost::python;
using namespace dda;

void registerSystemExport(py::class_<SceneLink, boost::noncopyable>& scene);  // pkg/py/SystemExport.cpp
void registerBaseMotion(py::class_<SceneLink, boost::noncopyable>& scene);    // pkg/py/BaseMotion.cpp

namespace {

Vector3 toVector(const py::object& item, const char* what) {
	if (py::len(item) != 3) {
		PyErr_Format(PyExc_ValueError, "%s must have 3 components", what);
		py::throw_error_already_set();
	}
	return Vector3(py::extract<double>(item[0])(), py::extract<double>(item[1])(), py::extract<double>(item[2])());
}

std::vector<Vector3> toPoints(const py::object& sequence, const char* what) {
	std::vector<Vector3> points;
	const long n = py::len(sequence);
	points.reserve(n);
	for (long i = 0; i < n; ++i)
		points.push_back(toVector(sequence[i], (std::string(what) + ": point " + std::to_string(i)).c_str()));
	return points;
}

template <class Vector>
py::tuple toTuple(const Vector& v) {
	py::list out;
	for (int i = 0; i < v.size(); ++i) out.append(v(i));
	return py::tuple(out);
}

py::list toList(const std::vector<Vector3>& points) {
	py::list out;
	for (const Vector3& p : points) out.append(p);
	return out;
}

int addBlock(SceneLink& scene, const py::object& points, double density, double young, double poisson,
             double frictionAngle, double cohesion, double tensileStrength, bool fixed, bool rigid) {
	return scene.world.addBlock(toPoints(points, "block vertices"),
	                            Material{density, young, poisson, frictionAngle, cohesion, tensileStrength}, fixed, rigid);
}

// Validates a block without adding it (ddaBlock calls this before making a body).
void checkBlock(const py::object& points, double density, double young, double poisson, double frictionAngle,
                double cohesion, double tensileStrength) {
	validateMaterial(Material{density, young, poisson, frictionAngle, cohesion, tensileStrength});
	buildConvexPolyhedron(toPoints(points, "block vertices"));
}

// hullCorners as a Python list of indices (ddaBlock(..., hull=True)).
py::list pythonHullCorners(const py::object& points) {
	py::list out;
	for (int i : hullCorners(toPoints(points, "hull points"))) out.append(i);
	return out;
}

// One tuple per sub-contact: (block i, block j, kind, structural type, state,
// normal from j to i, point, normal force [N], shear force on i [N], gap at the
// start of the step [m], bonded).
py::list contactList(const SceneLink& s) {
	py::list out;
	for (const Contact& c : s.world.contacts()) {
		out.append(py::make_tuple(c.key.blockI, c.key.blockJ, c.key.kind == ContactKind::VertexFace ? "VF" : "EE",
		                          contactTypeName(c.pairType), contactStateName(c.history.state), c.geometry.normal,
		                          c.point, c.history.normalForce, c.history.shearForce, c.geometry.gap,
		                          c.history.bonded));
	}
	return out;
}

void linkBody(SceneLink& scene, int block, int bodyId, const Vector3& position, const Eigen::Quaterniond& orientation,
              const py::object& localVertices) {
	scene.link(block, bodyId, position, orientation, toPoints(localVertices, "body vertices"));
}

py::list blockVertices(const SceneLink& scene, int i) { return toList(scene.world.block(i).vertices); }
py::list blockFaces(const SceneLink& scene, int i) {
	py::list faces;
	for (const auto& face : scene.world.block(i).shape->faces) {
		py::list f;
		for (int v : face) f.append(v);
		faces.append(py::tuple(f));
	}
	return faces;
}
py::list blockEdges(const SceneLink& scene, int i) {
	py::list edges;
	for (const auto& e : scene.world.block(i).shape->edges) edges.append(py::make_tuple(e[0], e[1]));
	return edges;
}
Vector3 blockCentroid(const SceneLink& s, int i) { return s.world.block(i).centroid; }
double blockVolume(const SceneLink& s, int i) { return s.world.block(i).volume; }
double blockMass(const SceneLink& s, int i) { return s.world.block(i).mass; }
Eigen::Matrix3d blockSecondMoment(const SceneLink& s, int i) { return s.world.block(i).secondMoment; }
py::tuple blockVelocity(const SceneLink& s, int i) { return toTuple(s.world.block(i).velocity); }
py::tuple blockStress(const SceneLink& s, int i) { return toTuple(s.world.block(i).stress); }
py::tuple blockStrain(const SceneLink& s, int i) { return toTuple(s.world.block(i).strain); }
Eigen::Quaterniond blockRotation(const SceneLink& s, int i) { return s.world.block(i).rotation; }
bool blockFixed(const SceneLink& s, int i) { return s.world.block(i).fixed; }
bool blockRigid(const SceneLink& s, int i) { return s.world.block(i).rigid; }
py::list blockFixedPoints(const SceneLink& s, int i) {
	py::list out;
	for (const FixedPoint& p : s.world.block(i).fixedPoints) out.append(p.position);
	return out;
}

void addFixedPoint(SceneLink& s, int i, const py::object& position, double stiffness) {
	s.world.addFixedPoint(i, toVector(position, "fixed point"), stiffness);
}
void addPointLoad(SceneLink& s, int i, const py::object& position, const py::object& force) {
	s.world.addPointLoad(i, toVector(position, "load position"), toVector(force, "load force"));
}
void setVelocity(SceneLink& s, int i, const py::object& v, const py::object& w) {
	s.world.setVelocity(i, toVector(v, "velocity"), toVector(w, "angular velocity"));
}
void setStress(SceneLink& s, int i, const py::object& stress) {
	if (py::len(stress) != 6) {
		PyErr_SetString(PyExc_ValueError, "stress must have 6 components (sxx, syy, szz, sxy, syz, szx) in Pa");
		py::throw_error_already_set();
	}
	Vector6 v;
	for (int k = 0; k < 6; ++k) v(k) = py::extract<double>(stress[k])();
	s.world.setStress(i, v);
}

double step(SceneLink& s, const IntegratorSettings& settings) {
	double dt;
	{
		// Release the GIL for the heavy work: nothing in World touches Python.
		PyThreadState* state = PyEval_SaveThread();
		try {
			dt = s.world.step(settings);
		} catch (...) {
			PyEval_RestoreThread(state);
			throw;
		}
		PyEval_RestoreThread(state);
	}
	return dt;
}

// The gap at the start of the step [m] of each sub-contact of the last step,
// in the order of contactList: what a check of the first step's gaps needs,
// at 32 bytes a contact instead of the few hundred of contactList's tuples
// (the whole list of 62,511 contacts of 50,000 slender blocks was 40 MB).
py::list contactGaps(const SceneLink& s) {
	py::list out;
	for (const Contact& c : s.world.contacts()) out.append(c.geometry.gap);
	return out;
}

// World::unsettledBlocks as a Python list of block indices.
py::list unsettledBlocks(const SceneLink& s) {
	py::list out;
	for (int b : s.world.unsettledBlocks()) out.append(b);
	return out;
}

// The narrow phase of one pair of blocks at their current geometry, as the
// integrator would see it with contact distance d0 [m]: None when farther
// apart, else (structural type, entrance normal, the pair's separation, the
// entrance axis's separation, [(kind, i owns, feature of
// i, feature of j, gap, normal, point i, point j), ...]) with i, j block
// indices of the sub-contact.
py::object detectPair(const SceneLink& s, int a, int b, double d0) {
	if (!(std::isfinite(d0) && d0 >= 0)) throw InputError("contact distance must be >= 0 and finite");
	if (a == b) throw InputError("a block cannot contact itself");
	const Block& A = s.world.block(a);
	const Block& B = s.world.block(b);
	// The integrator's settings for this pair (its last step's allowed displacement).
	const DetectionSettings settings =
	    pairDetectionSettings(boundingDiagonal(A), boundingDiagonal(B), d0, s.world.lastStep().allowedDisplacement);
	const auto result = detectPairContacts(BlockGeometry{A.shape.get(), &A.vertices, A.centroid},
	                                       BlockGeometry{B.shape.get(), &B.vertices, B.centroid}, settings);
	if (!result) return py::object();
	py::list subs;
	for (const SubContact& c : result->contacts) {
		subs.append(py::make_tuple(c.kind == ContactKind::VertexFace ? "VF" : "EE", c.firstIsA ? a : b,
		                           c.firstIsA ? b : a, c.feature1, c.feature2, c.gap, c.normal, c.pointI, c.pointJ));
	}
	return py::make_tuple(contactTypeName(result->type), result->normal, result->pairSeparation,
	                      result->separation, subs);
}

// Blocks overlapping when they enter the scene (dda/solver/InitialOverlaps.hpp):
// the scene's blocks from index firstUnchecked on and `added`, a list of
// (points, density, young, poisson, fixed) not yet in the scene, numbered
// blockCount + k. Returns [(a, b, depth [m], tolerance [m]), ...], deepest first.
py::list initialOverlaps(SceneLink& s, int firstUnchecked, const py::object& added, const IntegratorSettings& settings) {
	std::vector<Block> extra;
	for (long k = 0, n = py::len(added); k < n; ++k) {
		const py::object spec = added[k];
		Material material;
		material.density = py::extract<double>(spec[1])();
		material.young = py::extract<double>(spec[2])();
		material.poisson = py::extract<double>(spec[3])();
		extra.push_back(makeBlock(toPoints(spec[0], "block vertices"), material, py::extract<bool>(spec[4])()));
	}
	std::vector<const Block*> blocks;
	for (int i = 0; i < s.world.blockCount(); ++i) blocks.push_back(&s.world.block(i));
	for (const Block& b : extra) blocks.push_back(&b);
	py::list out;
	for (const InitialOverlap& o : findInitialOverlaps(blocks, std::max(0, firstUnchecked), settings))
		out.append(py::make_tuple(o.blockA, o.blockB, o.depth, o.tolerance));
	return out;
}

void setCollider(SceneLink& s, const std::string& name) {
	std::unique_ptr<Collider> collider = makeCollider(name);
	if (!collider) throw InputError("unknown collider '" + name + "' (known: " + colliderList() + ")");
	s.world.setCollider(std::move(collider));
}
std::string colliderName(const SceneLink& s) { return s.world.collider().name(); }

// MSC's critical length lambda [m] (0 = 3 x each block's size) and segments N
// for the whole scene; colliders without a cover raise (Collider::setCover).
void setCover(SceneLink& s, double criticalLength, int segments) {
	s.world.collider().setCover(criticalLength, segments);
}

// One entry per row of Statistics.def (a sub-dict for a row's group), then
// the energy account and the memory held, which have their own structs.
py::dict lastStep(const SceneLink& s) {
	const StepStatistics& st = s.world.lastStep();
	py::dict d, groups;
	auto put = [&](const char* group, const char* key, const py::object& value) {
		if (!*group) {
			d[key] = value;
			return;
		}
		if (!groups.has_key(group)) groups[group] = py::dict();
		py::dict sub = py::extract<py::dict>(groups[group]);
		sub[key] = value;
	};
#define DDA_STAT(type, name, group, key, unit, doc) put(group, #key, py::object(st.name));
#include "dda/solver/Statistics.def"
	d.update(groups);
	const World::MemoryUse use = s.world.memoryUse();
	py::dict memory;
	memory["collider"] = use.collider;
	memory["contacts"] = use.contacts;
	memory["narrowPhase"] = use.narrowPhase;
	memory["solver"] = use.solver;
	d["memory"] = memory;
	const EnergyAccount account = s.world.energy();
	py::dict energy;
	energy["kinetic"] = account.kinetic;
	energy["gravity"] = account.gravity;
	energy["gravityChange"] = account.gravityChange;
	energy["strain"] = account.strain;
	energy["contact"] = account.contact;
	energy["friction"] = account.friction;
	energy["damping"] = account.damping;
	energy["loads"] = account.loads;
	energy["boundaryWork"] = account.boundaryWork;
	energy["contactChanges"] = account.contactChanges;
	d["energy"] = energy;
	return d;
}

// _core.statisticsTable(): one dict per row of Statistics.def, in its order
// (group, key, kind, unit, doc), from which yade_dda.stats()'s docstring
// lists the step's report.
py::tuple statisticsTable() {
	py::list rows;
	auto row = [&](const char* group, const char* key, const char* kind, const char* unit, const char* doc) {
		py::dict r;
		r["group"] = group;
		r["key"] = key;
		r["kind"] = kind;
		r["unit"] = unit;
		r["doc"] = doc;
		rows.append(r);
	};
#define DDA_STAT(type, name, group, key, unit, doc) row(group, #key, #type, unit, doc);
#include "dda/solver/Statistics.def"
	return py::tuple(rows);
}

// _core.settingsTable(): one dict per row of Settings.def, in its order, from
// which yade_dda.engines makes DDAIntegrator's parameters, their checks and
// docstring, and tools/gen_docs.py doc/parameters.md.
const char* kindOf(double) { return "real"; }
const char* kindOf(int) { return "integer"; }
const char* kindOf(bool) { return "boolean"; }
const char* kindOf(const Vector3&) { return "vector"; }
const char* kindOf(const std::string&) { return "choice"; }

template <class T>
py::object toPython(const T& value) {
	return py::object(value);
}
py::object toPython(const Vector3& value) { return py::make_tuple(value.x(), value.y(), value.z()); }

void describe(py::dict& row, const Range& range, bool integer) {
	row["low"] = range.low;
	row["high"] = range.high;
	row["lowOpen"] = range.lowOpen;
	row["highOpen"] = range.highOpen;
	row["range"] = range.text(integer);
}
void describe(py::dict& row, const std::vector<std::string>& choices, bool) {
	py::list names;
	std::string text;
	for (const std::string& name : choices) {
		names.append(name);
		text += (text.empty() ? "one of " : ", ") + name;
	}
	row["choices"] = py::tuple(names);
	row["range"] = text;
}

template <class T, class Allowed>
py::dict settingRow(const char* name, const char* member, const T& value, const Allowed& allowed, const char* unit,
                    const char* doc) {
	py::dict row;
	row["name"] = name;
	row["member"] = member ? py::object(member) : py::object();
	row["kind"] = kindOf(value);
	row["default"] = toPython(value);
	describe(row, allowed, std::is_same<T, int>::value);
	row["unit"] = unit;
	row["doc"] = doc;
	return row;
}

py::tuple settingsTable() {
	const IntegratorSettings defaults;
	py::list rows;
#define DDA_SETTING(type, name, engineName, value, range, unit, doc) \
	rows.append(settingRow(#engineName, #name, defaults.name, range, unit, doc));
#define DDA_ENGINE_SETTING(type, name, value, range, unit, doc) \
	rows.append(settingRow(#name, nullptr, type(value), range, unit, doc));
#include "dda/solver/Settings.def"
	return py::tuple(rows);
}

py::tuple pythonColliderNames() {
	py::list names;
	for (const std::string& name : colliderNames()) names.append(name);
	return py::tuple(names);
}

// Convex parts [m] from Python (a list of corner lists), and back as lists of (x, y, z) tuples.
std::vector<std::vector<Vector3>> partsFrom(const py::object& parts) {
	std::vector<std::vector<Vector3>> corners;
	for (long k = 0, n = py::len(parts); k < n; ++k) corners.push_back(toPoints(parts[k], "part corners"));
	return corners;
}
py::list partsTo(const std::vector<std::vector<Vector3>>& parts) {
	py::list out;
	for (const std::vector<Vector3>& part : parts) {
		py::list corners;
		for (const Vector3& x : part) corners.append(py::make_tuple(x.x(), x.y(), x.z()));
		out.append(corners);
	}
	return out;
}

// A concave block from its convex parts (lists of corners [m]); returns its body's index.
int addConcaveBlock(SceneLink& s, const py::object& parts, double density, double young, double poisson,
                    double frictionAngle, double cohesion, double tensileStrength, bool fixed, bool rigid) {
	return s.world.addConcaveBlock(partsFrom(parts),
	                               Material{density, young, poisson, frictionAngle, cohesion, tensileStrength}, fixed,
	                               rigid);
}

// Raises ValueError naming the problem if the parts and material cannot make a concave block.
void checkConcaveBlock(const py::object& parts, double density, double young, double poisson, double frictionAngle,
                       double cohesion, double tensileStrength) {
	makeConcaveBlock(partsFrom(parts), Material{density, young, poisson, frictionAngle, cohesion, tensileStrength},
	                 false);
}

// conformParts on corner lists [m]: the parts split so that shared faces match.
py::list pythonConformParts(const py::object& parts) { return partsTo(conformParts(partsFrom(parts))); }

// convexDecomposition of a closed surface: points [m] and triangles (index triples).
py::list pythonConvexDecomposition(const py::object& points, const py::object& triangles) {
	std::vector<std::array<int, 3>> tris;
	for (long t = 0, n = py::len(triangles); t < n; ++t) {
		const py::object tri = triangles[t];
		if (py::len(tri) != 3) throw InputError("triangle " + std::to_string(t) + " must have 3 corner indices");
		tris.push_back({py::extract<int>(tri[0])(), py::extract<int>(tri[1])(), py::extract<int>(tri[2])()});
	}
	return partsTo(convexDecomposition(toPoints(points, "surface points"), tris));
}

void linkClump(SceneLink& s, int block, int clumpId, const Eigen::Quaterniond& orientation) {
	s.linkClump(block, clumpId, orientation);
}

// The parts of a block: one list of corners [m] per convex part (one for a convex block).
py::list blockParts(const SceneLink& s, int i) {
	py::list parts;
	const Block& b = s.world.block(i);
	for (int p = 0; p < b.partCount; ++p) parts.append(toList(s.world.block(i + p).vertices));
	return parts;
}

py::object bodyToBlock(const SceneLink& s, int bodyId) {
	const int block = s.blockOfBody(bodyId);
	return block < 0 ? py::object() : py::object(block);
}

// The scene's saved state as bytes (SceneLink::saveState), and back.
py::object saveState(const SceneLink& s) {
	const std::string state = s.saveState();
	return py::object(py::handle<>(PyBytes_FromStringAndSize(state.data(), static_cast<Py_ssize_t>(state.size()))));
}
void loadState(SceneLink& s, const py::object& state) {
	if (!PyBytes_Check(state.ptr())) throw InputError("a saved DDA state must be bytes");
	s.loadState(std::string(PyBytes_AS_STRING(state.ptr()), static_cast<std::size_t>(PyBytes_GET_SIZE(state.ptr()))));
}

// Concave blocks on the Scene class (World::addConcaveBlock, SceneLink::linkClump).
void registerConcaveBlocks(py::class_<SceneLink, boost::noncopyable>& scene) {
	scene
	    .def("addConcaveBlock", &addConcaveBlock,
	         (py::arg("parts"), py::arg("density"), py::arg("young"), py::arg("poisson"), py::arg("frictionAngle"),
	          py::arg("cohesion"), py::arg("tensileStrength"), py::arg("fixed"), py::arg("rigid") = false),
	         "A concave block of convex parts (World::addConcaveBlock); returns its body's block index.")
	    .def("linkClump", &linkClump, (py::arg("block"), py::arg("clumpId"), py::arg("orientation")),
	         "The YADE clump body that shows concave block `block` (its body's index), with its ori at creation.")
	    .def("parts", &blockParts, "The corners [m] of each convex part of block i (one list for a convex block).")
	    .def("partCount", +[](const SceneLink& s, int i) { return s.world.block(i).partCount; })
	    .def("partOfBody", +[](const SceneLink& s, int bodyId) {
		    const int part = s.partOfBody(bodyId);
		    return part < 0 ? py::object() : py::object(part);
	    }, "The block a body is linked to itself (a member's part), or None.")
	    .def("bodyOf", +[](const SceneLink& s, int i) { s.world.block(i); return s.world.bodyOf(i); },
	         "The block whose unknowns block i moves with (a concave block's body for its parts).")
	    .def("partPosition", +[](const SceneLink& s, int i) { return s.partPosition(i); },
	         "Block i's own centroid [m] (a part of a concave block: the part's).")
	    .def("clumps", +[](const SceneLink& s) {
		    py::list out;
		    for (const auto& [block, clump] : s.clumps()) out.append(py::make_tuple(block, clump.bodyId));
		    return out;
	    }, "[(block, clump id)] of the concave blocks' clumps.");
}

// The Scene class (a SceneLink): blocks, contacts, views of a block, steps, saving.
void registerScene() {
	py::class_<SceneLink, boost::noncopyable> scene("Scene", "The DDA state of one YADE scene; the core is the source of truth.");
	scene
	    .def("addBlock", &addBlock,
	         (py::arg("points"), py::arg("density"), py::arg("young"), py::arg("poisson"), py::arg("frictionAngle"),
	          py::arg("cohesion"), py::arg("tensileStrength"), py::arg("fixed"), py::arg("rigid") = false))
	    .def("contacts", &contactList)
	    .def("contactGaps", &contactGaps, "Gap [m] at the start of the last step of each sub-contact, as in contacts().")
	    .def("unsettledBlocks", &unsettledBlocks,
	         "Block indices still moving when a stage of the start from rest gave up (World::unsettledBlocks).")
	    .def("setCollider", &setCollider)
	    .def("setCover", &setCover)
	    .def("detectPair", &detectPair)
	    .def("initialOverlaps", &initialOverlaps)
	    .def("collider", &colliderName)
	    .def("linkBody", &linkBody)
	    .def("reserveBlocks", &SceneLink::reserveBlocks, py::arg("extra"),
	         "Room for extra more blocks (and their body links), added next one by one.")
	    .def("blockOfBody", &bodyToBlock)
	    .def("blockCount", &SceneLink::blockCount)
	    .def("vertices", &blockVertices)
	    .def("faces", &blockFaces)
	    .def("edges", &blockEdges)
	    .def("centroid", &blockCentroid)
	    .def("volume", &blockVolume)
	    .def("mass", &blockMass)
	    .def("secondMoment", &blockSecondMoment)
	    .def("velocity", &blockVelocity)
	    .def("stress", &blockStress)
	    .def("strain", &blockStrain)
	    .def("rotation", &blockRotation)
	    .def("isFixed", &blockFixed)
	    .def("isRigid", &blockRigid)
	    .def("fixedPoints", &blockFixedPoints)
	    .def("addFixedPoint", &addFixedPoint)
	    .def("addPointLoad", &addPointLoad)
	    .def("setVelocity", &setVelocity)
	    .def("setStress", &setStress)
	    .def("step", &step)
	    .def("lastStep", &lastStep)
	    .def("motionHalfSize", &SceneLink::motionHalfSize)
	    .def("time", &SceneLink::time)
	    .def("steps", &SceneLink::steps)
	    .def("saveState", &saveState, "The whole DDA scene (blocks, contacts and their history, counters) as bytes.")
	    .def("loadState", &loadState,
	         "Replaces this scene by a state from saveState; ValueError naming the problem (and no change) if it cannot.");
	registerConcaveBlocks(scene);
	registerSystemExport(scene);
	registerBaseMotion(scene);
}

// _core.YadeSync (pkg/py/YadeSync.hpp).
void registerYadeSync() {
	py::class_<YadeSync, boost::noncopyable>(
	    "YadeSync",
	    "Writes a Scene's state into YADE's containers from C++ (pkg/py/YadeSync.hpp): body states and shapes, "
	    "O.forces, O.interactions. One per DDA scene; it keeps YADE's objects it wrote to.",
	    py::init<py::object, py::object, py::object>(
	        (py::arg("geomClass"), py::arg("physClass"), py::arg("createInteraction"))))
	    .def("writeBodies", &YadeSync::writeBodies,
	         (py::arg("scene"), py::arg("bodies"), py::arg("all"), py::arg("threads") = 0),
	         "Writes moving blocks' (every block's if all) pos, ori, vel, angVel and, when strained, vertices into "
	         "their bodies (bodies: O.bodies); returns how many. The values are computed on `threads` threads "
	         "(0: OpenMP's count) from 1024 blocks on, and written from the calling thread.")
	    .def("writeViews", &YadeSync::writeViews,
	         (py::arg("scene"), py::arg("settings"), py::arg("forces"), py::arg("interactions"), py::arg("keep"),
	          py::arg("foreign")),
	         "Makes O.forces (forces) hold each block's force [N] and torque about its centroid [N m], gravity "
	         "excluded, and O.interactions (interactions) a real interaction per body pair with a closed contact "
	         "(none unless keep); foreign: [(id1, id2)] DDA pairs already there that it did not make. One pass over "
	         "the contacts; returns the pair count.")
	    .def("forgetBodies", &YadeSync::forgetBodies, "A body's state or shape object was replaced.")
	    .def("forgetInteractions", &YadeSync::forgetInteractions, "A script cleared O.interactions.")
	    .def("forgetInteraction", &YadeSync::forgetInteraction, (py::arg("id1"), py::arg("id2")),
	         "A script erased this interaction.")
	    .def("counters", +[](const YadeSync& y) {
		    const YadeSync::Counters c = y.counters();
		    py::dict out;
		    out["bodiesKept"] = c.bodiesKept;
		    out["interactionsKept"] = c.interactionsKept;
		    out["forceReadBacks"] = c.forceReadBacks;
		    return out;
	    }, "bodiesKept, interactionsKept: blocks and pairs whose YADE objects are kept; forceReadBacks: syncs "
	       "that read O.forces back because its probe disagreed.");
}

}  // namespace

BOOST_PYTHON_MODULE(_core) {
	py::docstring_options options(true, true, false);

	py::def("checkBlock", &checkBlock,
	        (py::arg("points"), py::arg("density"), py::arg("young"), py::arg("poisson"), py::arg("frictionAngle") = 0.0,
	         py::arg("cohesion") = 0.0, py::arg("tensileStrength") = 0.0),
	        "Raises ValueError naming the problem if the points and material cannot make a DDA block.");

	py::def("checkConcaveBlock", &checkConcaveBlock,
	        (py::arg("parts"), py::arg("density"), py::arg("young"), py::arg("poisson"), py::arg("frictionAngle") = 0.0,
	         py::arg("cohesion") = 0.0, py::arg("tensileStrength") = 0.0),
	        "Raises ValueError naming the problem if the convex parts (corner lists [m]) and material cannot make a "
	        "concave block (a part no convex polyhedron, parts that overlap, share a face only in part, or are not "
	        "one piece).");

	py::def("convexDecomposition", &pythonConvexDecomposition, (py::arg("points"), py::arg("triangles")),
	        "The convex parts (corner lists [m]) of the solid a closed triangulated surface bounds (CGAL's "
	        "convex_decomposition_3, exact); ValueError naming the problem (open, non-manifold, self-intersecting).");
	py::def("conformParts", &pythonConformParts, py::arg("parts"),
	        "The convex parts (corner lists [m]) split so that wherever two share a face region, one face lies "
	        "wholly on the other (what a concave block needs); ValueError naming the problem.");

	py::scope().attr("__version__") = YADE_DDA_VERSION;  // CMakeLists.txt's project version

	py::def("hullCorners", &pythonHullCorners, py::arg("points"),
	        "Indices of the points [m] that are the corners of their convex hull, in input order (points inside the "
	        "hull, repeats and points on a face or an edge of it within the coplanar tolerance are left out); "
	        "ValueError for fewer than 4 points, NaN or inf, or no volume.");

	py::scope().attr("mscMaxSegments") = kMaxCoverSegments;

	py::def("statisticsTable", &statisticsTable,
	        "One dict per statistic of a step's report (pkg/dda/solver/Statistics.def, in its order): group ('' "
	        "for a top-level key of stats(), else its sub-dict), key, kind (C++ type), unit, doc.");
	py::def("settingsTable", &settingsTable,
	        "Every DDAIntegrator parameter, one dict per row of pkg/dda/solver/Settings.def: name, member (the "
	        "IntegratorSettings attribute; None for the engine's own), kind, default, range (its text), low, high, "
	        "lowOpen, highOpen (numbers) or choices (names), unit, doc.");
	py::def("colliderNames", &pythonColliderNames, "The broad phases of the core, by name (DESS first, the default).");
	void registerRockMass(); registerRockMass();  // cutRockMass and its predicates (pkg/py/RockMass.cpp)

	py::class_<IntegratorSettings> settingsClass(
	    "IntegratorSettings", "Parameters of one DDA step (pkg/dda/solver/Settings.def; DDAIntegrator's docstring).");
#define DDA_SETTING(type, name, engineName, value, range, unit, doc) \
	settingsClass.def_readwrite(#name, &IntegratorSettings::name, doc);
#include "dda/solver/Settings.def"

	registerScene();

	registerYadeSync();
}
