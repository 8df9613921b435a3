// Scene.coupledSystem: the coupled system K D = F of the last step's last
// solve, as raw arrays for yade_dda.coupledSystem (py/yade_dda/scene.py),
// which turns them into NumPy arrays: for studying the equations outside the
// integrator (another solver, a distributed solve on a saved system).
#include "SceneLink.hpp"

#include <boost/python.hpp>

#include <string>
#include <vector>

namespace py = boost::python;
using namespace dda;

namespace {

template <class T>
py::object bytesOf(const std::vector<T>& values) {
	const std::string raw(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
	return py::object(py::handle<>(PyBytes_FromStringAndSize(raw.data(), static_cast<Py_ssize_t>(raw.size()))));
}

// A 12x12 block's entries row by row; the diagonal blocks from their lower
// triangle (the assembly's), so symmetric.
void appendRows(std::vector<double>& out, const Matrix12& m, bool symmetricLower) {
	const Matrix12 full = symmetricLower ? Matrix12(m.selfadjointView<Eigen::Lower>()) : m;
	for (int i = 0; i < 12; ++i)
		for (int j = 0; j < 12; ++j) out.push_back(full(i, j));
}

py::dict coupledSystem(const SceneLink& s) {
	const OpenCloseIteration& iteration = s.world.openClose();
	const CoupledSystem& system = iteration.coupledSystem();
	const std::vector<int>& moving = iteration.moving();
	const std::vector<Vector3>& centroids = iteration.solveCentroids();
	const int rows = system.blocks();
	std::vector<int> blocks, sizes, links;
	std::vector<double> diagonal, offDiagonal, force, centre;
	for (int slot = 0; slot < rows; ++slot) {
		const int k = system.slotBlocks()[slot];
		blocks.push_back(moving[k]);
		sizes.push_back(system.slotUnknowns()[slot]);
		appendRows(diagonal, system.diagonalBlocks()[slot], true);
		for (int i = 0; i < 12; ++i) force.push_back(system.forces()[slot](i));
		for (int i = 0; i < 3; ++i) centre.push_back(k < static_cast<int>(centroids.size()) ? centroids[k](i) : 0.0);
	}
	for (std::size_t l = 0; l < system.linkSlots().size(); ++l) {
		links.push_back(system.linkSlots()[l].first);
		links.push_back(system.linkSlots()[l].second);
		appendRows(offDiagonal, system.offDiagonalBlocks()[l], false);
	}
	py::dict out;
	out["rows"] = rows;
	out["links"] = static_cast<int>(system.linkSlots().size());
	out["blocks"] = bytesOf(blocks);
	out["sizes"] = bytesOf(sizes);
	out["linkRows"] = bytesOf(links);
	out["diagonal"] = bytesOf(diagonal);
	out["offDiagonal"] = bytesOf(offDiagonal);
	out["force"] = bytesOf(force);
	out["centroids"] = bytesOf(centre);
	out["componentStarts"] = bytesOf(rows > 0 ? system.componentStarts() : std::vector<int>{0});
	return out;
}

}  // namespace

// Called from module.cpp's registerScene.
void registerSystemExport(py::class_<SceneLink, boost::noncopyable>& scene) {
	scene.def("coupledSystem", &coupledSystem,
	          "The coupled system of the last step's last solve as raw arrays (yade_dda.coupledSystem).");
}
