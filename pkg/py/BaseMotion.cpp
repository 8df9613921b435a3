// Scene.addBaseMotion and its queries: prescribed motions of fixed blocks
// (dda::BaseMotion, World::addBaseMotion) for yade_dda.baseMotion and
// yade_dda.baseMotionState (py/yade_dda/shaking.py).
#include "SceneLink.hpp"

#include <boost/python.hpp>

#include <string>
#include <vector>

namespace py = boost::python;
using namespace dda;

namespace {

py::tuple tupleOf(const Vector3& v) { return py::make_tuple(v.x(), v.y(), v.z()); }

int addBaseMotion(SceneLink& s, const py::list& blocks, const std::string& kind, const py::list& times,
                  const py::list& values, double start) {
	if (kind != "acceleration" && kind != "velocity")
		throw InputError("a base motion is a table of 'acceleration' or 'velocity', got '" + kind + "'");
	std::vector<int> indices;
	for (py::ssize_t k = 0; k < py::len(blocks); ++k) indices.push_back(py::extract<int>(blocks[k]));
	std::vector<double> t;
	std::vector<Vector3> v;
	for (py::ssize_t k = 0; k < py::len(times); ++k) t.push_back(py::extract<double>(times[k]));
	for (py::ssize_t k = 0; k < py::len(values); ++k) {
		const py::object row = values[k];
		v.emplace_back(py::extract<double>(row[0]), py::extract<double>(row[1]), py::extract<double>(row[2]));
	}
	const BaseMotion::Kind which = kind == "velocity" ? BaseMotion::Kind::Velocity : BaseMotion::Kind::Acceleration;
	return s.world.addBaseMotion(indices, BaseMotion(which, std::move(t), std::move(v), start));
}

const BaseMotion& motionOf(const SceneLink& s, int motion) {
	if (motion < 0 || motion >= s.world.baseMotionCount())
		throw InputError("no base motion " + std::to_string(motion) + " (the scene has " +
		                 std::to_string(s.world.baseMotionCount()) + ")");
	return s.world.baseMotion(motion);
}

py::tuple baseMotionAt(const SceneLink& s, int motion, double time) {
	const BaseMotion& m = motionOf(s, motion);
	// Vector3 (YADE's minieigen converters, as the block views').
	return py::make_tuple(m.displacementAt(time), m.velocity(time), m.acceleration(time));
}

py::list baseMotionBlocks(const SceneLink& s, int motion) {
	motionOf(s, motion);
	py::list out;
	for (const int b : s.world.baseMotionBlocks(motion)) out.append(b);
	return out;
}

py::tuple baseMotionTable(const SceneLink& s, int motion) {
	const BaseMotion& m = motionOf(s, motion);
	py::list times, values;
	for (const double t : m.times()) times.append(t);
	for (const Vector3& v : m.values()) values.append(tupleOf(v));
	return py::make_tuple(m.kind() == BaseMotion::Kind::Velocity ? "velocity" : "acceleration", m.start(), times,
	                      values);
}

}  // namespace

// Called from module.cpp's registerScene.
void registerBaseMotion(py::class_<SceneLink, boost::noncopyable>& scene) {
	scene.def("addBaseMotion", &addBaseMotion,
	          (py::arg("blocks"), py::arg("kind"), py::arg("times"), py::arg("values"), py::arg("start")),
	          "A prescribed translation of fixed blocks (indices) from a table of times [s] and 3-vectors of "
	          "acceleration [m/s^2] or velocity [m/s], its time 0 at the scene time start [s]; returns its index.");
	scene.def("baseMotionCount", +[](const SceneLink& s) { return s.world.baseMotionCount(); });
	scene.def("baseMotionAt", &baseMotionAt, (py::arg("motion"), py::arg("time")),
	          "(displacement [m] since its start, velocity [m/s], acceleration [m/s^2]) of a motion at a scene time.");
	scene.def("baseMotionBlocks", &baseMotionBlocks, "The blocks (parts) a motion moves.");
	scene.def("baseMotionTable", &baseMotionTable, "(kind, start [s], times [s], values) of a motion.");
}
