// Writes the DDA state into YADE's containers from C++ (the sync of
// yade_dda.scene): body states and deformed shapes, O.forces, and the real
// interactions of O.interactions (what Views.cpp computes).
//
// Every write goes through YADE's own Python attributes (YADE ships no
// headers, DESIGN.md), but from a C++ loop, without Python objects made per
// block: the State, Polyhedra, PolyhedraGeom and PolyhedraPhys objects are
// looked up once and kept, and the vectors handed to YADE's setters are a few
// Python Vector3/Quaternion objects refilled in place (a setter copies the
// value). The caches hold because:
//   - YADE's bodies of DDA blocks stay while the scene lives: erasing a block
//     is refused, clear/replace/O.load/O.reset give a new DDA scene and with
//     it a new YadeSync (yade_dda.hooks);
//   - a script that replaces a block's state or shape object (Body.state and
//     Body.shape setters) or erases or clears interactions goes through
//     yade_dda.hooks, which tells this object to forget what it kept;
//   - the interactions are real ones (geom and phys set), which YADE's
//     colliders never erase, and none are kept while a YADE InteractionLoop
//     runs (views.py).
// O.forces: forceWrites adds to each block's force the difference between the
// new value and what this object last wrote; one probe (a block whose force
// it believes nonzero) checks that nobody reset or changed them since. On a
// mismatch (a ForceResetter ran, O.forces.reset(), permanent forces) every
// block's force is read back and the difference added, as the Python sync
// did. See doc/guide/explanation.md, "What YADE sees".
#pragma once

#include "SceneLink.hpp"
#include "dda/solver/IntegratorSettings.hpp"

#include <boost/python.hpp>

#include <map>
#include <utility>
#include <vector>

namespace dda {

namespace py = boost::python;

// One body pair with a closed DDA contact, as YADE's PolyhedraGeom and
// PolyhedraPhys show it (Views.cpp): id1 < id2; normal from id1 to id2;
// normalForce + shearForce is the force on id2 [N].
struct PairView {
	int id1, id2;
	Vector3 point, normal, normalForce, shearForce;
	double kn, ks, tanPhi;  // [N/m], [N/m], [-]
};

// A block's force [N] and torque about its centroid [N m], gravity excluded.
struct BodyForce {
	int bodyId;
	Vector3 force, torque;
};

// Views.cpp, in one pass over the contacts: the pairs in body order (none
// unless withPairs), and one entry per linked block in block order.
struct ContactViews {
	std::vector<PairView> pairs;
	std::vector<BodyForce> bodies;
};
ContactViews contactViews(const SceneLink& s, const IntegratorSettings& settings, bool withPairs);

class YadeSync {
public:
	// geomClass, physClass: YADE's PolyhedraGeom and PolyhedraPhys;
	// createInteraction: utils.createInteraction.
	YadeSync(py::object geomClass, py::object physClass, py::object createInteraction);

	// Moving blocks' (every block's if all) position, orientation, velocity,
	// angular velocity, and vertices when strained since the last write;
	// returns how many bodies were written. The values are computed first,
	// on `threads` threads (0: OpenMP's count) from kMinBlocksForThreads
	// blocks on, then written from the calling thread (YADE's setters hold
	// Python's lock).
	int writeBodies(SceneLink& s, const py::object& bodies, bool all, int threads = 0);
	// O.forces (forces) holds each block's force and torque, and
	// O.interactions (interactions) the pairs' views when keep (else none of
	// them); foreign: DDA pairs already in O.interactions that this object
	// did not make (a loaded scene's), erased unless current. Returns the
	// pair count.
	int writeViews(const SceneLink& s, const IntegratorSettings& settings, const py::object& forces,
	               const py::object& interactions, bool keep, const py::list& foreign);

	void forgetBodies();        // a body's state or shape object was replaced
	void forgetInteractions();                 // a script cleared the interactions
	void forgetInteraction(int id1, int id2);  // a script erased one
	struct Counters {
		int bodiesKept, interactionsKept;  // whose YADE objects are kept
		long forceReadBacks;               // syncs that read O.forces back (a probe disagreed)
	};
	Counters counters() const;

private:
	struct BodyObjects {
		py::object state, shape;  // None until looked up
	};
	struct PairObjects {
		py::object geom, phys;
	};
	BodyObjects& bodyObjects(const py::object& bodies, int block, int bodyId);
	static BodyObjects lookUp(const py::object& bodies, int bodyId);
	int writeClumps(SceneLink& s, const py::object& bodies, bool all);
	PairObjects pairObjects(const py::object& interactions, int id1, int id2);
	// What writeBodies writes into one body, computed before any write.
	struct BodyValues {
		bool write = false, vertices = false;  // whether the body is written, with its vertices
		Vector3 position, velocity, angularVelocity;
		Eigen::Quaterniond orientation;
		std::vector<Vector3> local;  // its vertices in its frame (when `vertices`; kept for its capacity)
	};
	void prepareBodies(const SceneLink& s, bool all, int threads);
	struct VertexList {
		py::object list;               // of `count` Vector3 objects...
		std::vector<Vector3*> values;  // ... and their values, refilled before each write
	};
	const VertexList& vertexList(std::size_t count);
	void setVector(PyObject* target, PyObject* name, const Vector3& value);
	void addForces(const std::vector<BodyForce>& target, const py::object& forces, bool readBack);
	void writeForces(const std::vector<BodyForce>& target, const py::object& forces);
	int writeInteractions(const std::vector<PairView>& current, const py::object& interactions, bool keep,
	                      const py::list& foreign);

	py::object geomClass_, physClass_, createInteraction_;
	py::object vector_, quaternion_;  // refilled for each setter call
	Vector3* vectorValue_;
	Eigen::Quaterniond* quaternionValue_;
	std::vector<BodyObjects> bodies_;                  // per block
	std::vector<BodyValues> bodyValues_;               // per block, prepareBodies' results
	std::map<int, BodyObjects> clumpObjects_;          // per concave block's body: its clump's
	bool resend_ = false;                              // write every body in full next (forgetBodies)
	std::map<std::size_t, VertexList> vertexLists_;    // per vertex count
	std::map<std::pair<int, int>, PairObjects> pairs_;  // the interactions this object keeps
	std::vector<BodyForce> written_;                    // per block: what O.forces holds of it, as written
	long forceReadBacks_ = 0;
};

}  // namespace dda
