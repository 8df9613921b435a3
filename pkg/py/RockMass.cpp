// _core.cutRockMass: the binding of the rock-mass cutter
// (dda/geometry/RockMassCutter.hpp). py/yade_dda/rockmass.py validates the
// user's joint dicts and calls this with normalised ones; the result comes
// back as plain tuples and dicts, which rockmass.py wraps.
#include "dda/core/Errors.hpp"
#include "dda/geometry/ConvexParts.hpp"
#include "dda/geometry/RockMassCutter.hpp"

#include <boost/python.hpp>

#include <algorithm>
#include <string>

namespace py = boost::python;

namespace dda {
namespace {

using namespace rockmass;

Vector3 pointOf(const py::object& item) {
	if (py::len(item) != 3) throw InputError("a point must have 3 coordinates");
	return Vector3(py::extract<double>(item[0])(), py::extract<double>(item[1])(), py::extract<double>(item[2])());
}

std::vector<Vector3> pointsOf(const py::object& sequence) {
	std::vector<Vector3> points;
	for (long i = 0, n = py::len(sequence); i < n; ++i) points.push_back(pointOf(sequence[i]));
	return points;
}

SpacingDistribution distributionOf(const std::string& name) {
	if (name == "fixed") return SpacingDistribution::Fixed;
	if (name == "exponential") return SpacingDistribution::Exponential;
	if (name == "lognormal") return SpacingDistribution::Lognormal;
	throw InputError("unknown spacing distribution '" + name + "' (known: fixed, exponential, lognormal)");
}

// A joint dict as rockmass.py normalises it: 'kind' and that kind's keys.
JointSpec jointOf(const py::dict& d) {
	JointSpec spec;
	const std::string kind = py::extract<std::string>(d["kind"]);
	if (kind == "set") {
		spec.kind = JointSpec::Kind::Set;
		spec.dip = py::extract<double>(d["dip"]);
		spec.dipDirection = py::extract<double>(d["dipDirection"]);
		spec.spacing = py::extract<double>(d["spacing"]);
		spec.origin = pointOf(d["origin"]);
		spec.persistence = py::extract<double>(d["persistence"]);
		spec.fisherK = py::extract<double>(d["fisherK"]);
		spec.distribution = distributionOf(py::extract<std::string>(d["spacingDistribution"]));
		spec.spacingStd = py::extract<double>(d["spacingStd"]);
	} else if (kind == "plane" || kind == "excavate") {
		spec.kind = kind == "plane" ? JointSpec::Kind::Plane : JointSpec::Kind::ExcavateHalfSpace;
		spec.point = pointOf(d["point"]);
		spec.normal = pointOf(d["normal"]);
		if (kind == "plane") spec.persistence = py::extract<double>(d["persistence"]);
	} else if (kind == "excavateRegion") {
		spec.kind = JointSpec::Kind::ExcavateRegion;
		const py::object regions = d["regions"];
		for (long r = 0, n = py::len(regions); r < n; ++r) spec.regions.push_back(pointsOf(regions[r]));
	} else {
		throw InputError("unknown joint kind '" + kind + "'");
	}
	return spec;
}

py::tuple tupleOf(const Vector3& v) { return py::make_tuple(v.x(), v.y(), v.z()); }

// Python objects through the C API: a 50,000-block result is about 2 million of them, which
// Boost.Python's converters made 2.5 times slower.
PyObject* checked(PyObject* object) {
	if (!object) py::throw_error_already_set();
	return object;
}

PyObject* pointTuple(const Vector3& v) {
	PyObject* t = checked(PyTuple_New(3));
	for (int k = 0; k < 3; ++k) PyTuple_SET_ITEM(t, k, checked(PyFloat_FromDouble(v[k])));
	return t;
}

template <class Ints>
PyObject* intTuple(const Ints& values) {
	PyObject* t = checked(PyTuple_New(static_cast<Py_ssize_t>(values.size())));
	Py_ssize_t i = 0;
	for (int v : values) PyTuple_SET_ITEM(t, i++, checked(PyLong_FromLong(v)));
	return t;
}

template <class Items, class Make>
PyObject* listOf(const Items& items, Make make) {
	PyObject* list = checked(PyList_New(static_cast<Py_ssize_t>(items.size())));
	Py_ssize_t i = 0;
	for (const auto& item : items) PyList_SET_ITEM(list, i++, make(item));
	return list;
}

// (part, corners, faces, face planes, volume, problem, corner planes)
py::object blockTuple(const RockBlock& b) {
	PyObject* t = checked(PyTuple_New(7));
	PyTuple_SET_ITEM(t, 0, checked(PyLong_FromLong(b.part)));
	PyTuple_SET_ITEM(t, 1, listOf(b.corners, pointTuple));
	PyTuple_SET_ITEM(t, 2, listOf(b.faces, intTuple<std::vector<int>>));
	PyTuple_SET_ITEM(t, 3, intTuple(b.facePlanes));
	PyTuple_SET_ITEM(t, 4, checked(PyFloat_FromDouble(b.volume)));
	PyTuple_SET_ITEM(t, 5, checked(PyUnicode_FromStringAndSize(b.problem.data(), static_cast<Py_ssize_t>(b.problem.size()))));
	PyTuple_SET_ITEM(t, 6, listOf(b.cornerPlanes, intTuple<PlaneTriple>));
	return py::object(py::handle<>(t));
}

py::dict statsOf(const CutStatistics& s) {
	py::dict d;
	d["planes"] = s.planes;
	d["cuts"] = s.cuts;
	d["skippedCuts"] = s.skippedCuts;
	d["classified"] = s.classified;
	d["vertices"] = s.vertices;
	d["mergedSlivers"] = s.mergedSlivers;
	d["snappedCorners"] = s.snappedCorners;
	d["signsFromBounds"] = s.predicates.boundsDecided;
	d["signsFromIntervals"] = s.predicates.intervalDecided;
	d["signsExact"] = s.predicates.exactDecided;
	py::dict seconds;
	seconds["planes"] = s.secondsPlanes;
	seconds["cut"] = s.secondsCut;
	seconds["excavate"] = s.secondsExcavate;
	seconds["slivers"] = s.secondsSlivers;
	seconds["output"] = s.secondsOutput;
	d["seconds"] = seconds;
	return d;
}

py::dict pythonCutRockMass(const py::object& parts, const py::object& joints, unsigned long long seed,
                           double minVolume, bool checkShapes) {
	std::vector<std::vector<Vector3>> partPoints;
	for (long i = 0, n = py::len(parts); i < n; ++i) partPoints.push_back(pointsOf(parts[i]));
	std::vector<JointSpec> specs;
	for (long i = 0, n = py::len(joints); i < n; ++i) specs.push_back(jointOf(py::extract<py::dict>(joints[i])));
	CutOptions options;
	options.seed = seed;
	options.minVolume = minVolume;
	options.checkShapes = checkShapes;
	RockMass mass;
	{
		PyThreadState* state = PyEval_SaveThread();  // nothing below touches Python
		try {
			mass = cutRockMass(partPoints, specs, options);
		} catch (...) {
			PyEval_RestoreThread(state);
			throw;
		}
		PyEval_RestoreThread(state);
	}
	py::list blocks, slivers, planes;
	for (const RockBlock& b : mass.blocks) blocks.append(blockTuple(b));
	for (const RockBlock& b : mass.slivers) slivers.append(blockTuple(b));
	for (const PlaneRecord& r : mass.planes)
		planes.append(py::make_tuple(planeKindName(r.kind), r.source, r.number, tupleOf(r.plane.normal), r.plane.offset,
		                             r.persistence));
	py::dict out;
	out["blocks"] = blocks;
	out["slivers"] = slivers;
	out["planes"] = planes;
	out["domainVolume"] = mass.domainVolume;
	out["minVolume"] = mass.minVolume;
	out["stats"] = statsOf(mass.stats);
	return out;
}

// The exact predicates, for tests: sign of n_l . x - d_l at the vertex of planes (i, j, k).
int pythonVertexSide(const py::object& planes, int i, int j, int k, int l) {
	std::vector<CutPlane> list;
	for (long p = 0, n = py::len(planes); p < n; ++p)
		list.push_back(CutPlane{pointOf(planes[p][0]), py::extract<double>(planes[p][1])});
	PlaneTriple t{i, j, k};
	std::sort(t.begin(), t.end());
	const int n = static_cast<int>(list.size());
	if (t[0] < 0 || t[2] >= n || l < 0 || l >= n || t[0] == t[1] || t[1] == t[2])
		throw InputError("plane indices must be distinct and below " + std::to_string(n));
	if (tripleSign(list, t) == 0) throw InputError("the three planes do not meet in one point");
	return vertexSide(list, t, vertexBounds(list, t), l);
}

py::tuple pythonPole(double dip, double dipDirection) { return tupleOf(poleOf(dip, dipDirection)); }

// sharedFaces of blocks given as (corners, faces): [(a, f, b, g, area [m^2])], the caller's face indices.
py::list pythonSharedFaces(const py::object& blocks) {
	std::vector<ConvexPolyhedron> polyhedra;
	for (long i = 0, n = py::len(blocks); i < n; ++i) {
		ConvexPolyhedron p;
		p.vertices = pointsOf(blocks[i][0]);
		const py::object faces = blocks[i][1];
		for (long f = 0, m = py::len(faces); f < m; ++f) {
			std::vector<int> face;
			for (long k = 0, c = py::len(faces[f]); k < c; ++k) {
				const int v = py::extract<int>(faces[f][k])();
				if (v < 0 || v >= static_cast<int>(p.vertices.size()))
					throw InputError("block " + std::to_string(i) + ": face " + std::to_string(f) + " has corner " +
					                 std::to_string(v) + ", out of range");
				face.push_back(v);
			}
			if (face.size() < 3) throw InputError("block " + std::to_string(i) + ": face " + std::to_string(f) +
			                                      " has fewer than 3 corners");
			p.faces.push_back(face);
		}
		polyhedra.push_back(std::move(p));
	}
	py::list out;
	for (const SharedFace& s : sharedFaces(polyhedra)) out.append(py::make_tuple(s.a, s.f, s.b, s.g, s.area));
	return out;
}

}  // namespace
}  // namespace dda

// Called from module.cpp's BOOST_PYTHON_MODULE (declared there, at global scope).
void registerRockMass() {
	using namespace dda;
	py::def("cutRockMass", &pythonCutRockMass,
	        (py::arg("parts"), py::arg("joints"), py::arg("seed"), py::arg("minVolume"), py::arg("checkShapes")),
	        "The core of yade_dda.cutRockMass (pkg/dda/geometry/RockMassCutter.hpp): parts are corner lists [m], "
	        "joints normalised dicts; returns a dict of blocks, slivers, planes, domainVolume, minVolume, stats.");
	py::def("vertexSide", &pythonVertexSide,
	        (py::arg("planes"), py::arg("i"), py::arg("j"), py::arg("k"), py::arg("l")),
	        "Exact sign of n_l . x - d_l at the intersection of planes i, j, k; planes are (normal, offset) pairs.");
	py::def("sharedFaces", &pythonSharedFaces, py::arg("blocks"),
	        "Faces of different blocks ((corners, faces) each) that are opposed, coplanar and share area: "
	        "[(a, f, b, g, area [m^2])], a < b (dda/geometry/ConvexParts.hpp).");
	py::def("pole", &pythonPole, (py::arg("dip"), py::arg("dipDirection")),
	        "Upward unit normal of a plane of dip and dip direction [deg]: (sin d sin a, sin d cos a, cos d).");
}
