// The C++ sync into YADE's containers (YadeSync.hpp says what is kept and why).
#include "YadeSync.hpp"

#include "dda/solver/StepClock.hpp"

#include <omp.h>

#include <algorithm>
#include <string>

namespace dda {

namespace {

// Attribute and method names, interned once.
PyObject* name(const char* text) { return PyUnicode_InternFromString(text); }

struct Names {
	PyObject *state = name("state"), *shape = name("shape"), *pos = name("pos"), *ori = name("ori"),
	         *vel = name("vel"), *angVel = name("angVel"), *v = name("v"), *geom = name("geom"), *phys = name("phys"),
	         *contactPoint = name("contactPoint"), *normal = name("normal"), *normalForce = name("normalForce"),
	         *shearForce = name("shearForce"), *kn = name("kn"), *ks = name("ks"),
	         *tanPhi = name("tangensOfFrictionAngle");
};

const Names& names() {
	static const Names instance;
	return instance;
}

void check(int status) {
	if (status < 0) py::throw_error_already_set();
}

py::object owned(PyObject* object) {
	if (!object) py::throw_error_already_set();
	return py::object(py::handle<>(object));
}

void setDouble(PyObject* target, PyObject* attribute, double value) {
	const py::object number = owned(PyFloat_FromDouble(value));
	check(PyObject_SetAttr(target, attribute, number.ptr()));
}

Vector3 readVector(const py::object& value) { return py::extract<Vector3>(value)(); }

}  // namespace

YadeSync::YadeSync(py::object geomClass, py::object physClass, py::object createInteraction)
    : geomClass_(geomClass), physClass_(physClass), createInteraction_(createInteraction),
      vector_(Vector3(Vector3::Zero())), quaternion_(Eigen::Quaterniond::Identity()) {
	// References into the Python objects' own values: refilled before each setter call.
	vectorValue_ = &py::extract<Vector3&>(vector_)();
	quaternionValue_ = &py::extract<Eigen::Quaterniond&>(quaternion_)();
}

void YadeSync::setVector(PyObject* target, PyObject* attribute, const Vector3& value) {
	*vectorValue_ = value;
	check(PyObject_SetAttr(target, attribute, vector_.ptr()));
}

YadeSync::BodyObjects& YadeSync::bodyObjects(const py::object& bodies, int block, int bodyId) {
	if (static_cast<int>(bodies_.size()) <= block) bodies_.resize(block + 1);
	BodyObjects& kept = bodies_[block];
	if (kept.state.is_none()) kept = lookUp(bodies, bodyId);
	return kept;
}

YadeSync::BodyObjects YadeSync::lookUp(const py::object& bodies, int bodyId) {
	const py::object body = owned(PyObject_GetItem(bodies.ptr(), py::object(bodyId).ptr()));
	if (body.is_none()) {
		PyErr_Format(PyExc_RuntimeError,
		             "body %d of a DDA block was removed from O.bodies; removing DDA blocks mid-run is not supported",
		             bodyId);
		py::throw_error_already_set();
	}
	return BodyObjects{owned(PyObject_GetAttr(body.ptr(), names().state)),
	                   owned(PyObject_GetAttr(body.ptr(), names().shape))};
}

const YadeSync::VertexList& YadeSync::vertexList(std::size_t count) {
	auto found = vertexLists_.find(count);
	if (found == vertexLists_.end()) {
		py::list list;
		std::vector<Vector3*> values;
		for (std::size_t k = 0; k < count; ++k) {
			py::object vertex{Vector3(Vector3::Zero())};
			values.push_back(&py::extract<Vector3&>(vertex)());
			list.append(vertex);
		}
		found = vertexLists_.emplace(count, VertexList{list, values}).first;
	}
	return found->second;
}

// Everything a body's write needs, per block: pure C++ on the blocks and
// links (nothing of Python), each block its own entry, so on any thread.
void YadeSync::prepareBodies(const SceneLink& s, bool all, int threads) {
	const int n = s.world.blockCount();
	if (static_cast<int>(bodyValues_.size()) < n) bodyValues_.resize(n);
#pragma omp parallel for schedule(static, 64) num_threads(threads > 0 ? threads : omp_get_max_threads()) \
    if (n >= kMinBlocksForThreads)
	for (int i = 0; i < n; ++i) {
		BodyValues& values = bodyValues_[i];
		const Block& b = s.world.block(i);
		const BodyLink* link = s.bodyLink(i);
		const bool first = !link || !link->synced || resend_;  // a first write (or to objects new to this writer)
		values.write = link && !(b.fixed && !b.shaken && !first && !all);  // a still fixed block once
		if (!values.write) continue;
		// A part of a concave block: its own centroid, moving with its body.
		const Block& moving = b.isPart() ? s.world.block(s.world.bodyOf(i)) : b;
		values.position = b.isPart() ? s.partPosition(i) : b.centroid;
		values.orientation = s.bodyOrientation(i);
		values.velocity = b.isPart() ? s.partVelocity(i, values.position) : b.velocity.head<3>();
		values.angularVelocity = moving.velocity.segment<3>(3);
		// Vertices in the body's local frame and vertex order: at the first
		// write (YADE's frame is at YADE's centroid, the core's at its own:
		// they differ by round-off), then when strained since the last one.
		values.vertices = all || first || b.unsyncedStrain > SceneLink::kVertexSyncStrain;
		if (values.vertices) s.localVertices(i, values.position, values.local);
	}
}

int YadeSync::writeBodies(SceneLink& s, const py::object& bodies, bool all, int threads) {
	const Names& n = names();
	prepareBodies(s, all, threads);
	int written = 0;
	for (int i = 0; i < s.world.blockCount(); ++i) {
		const BodyValues& values = bodyValues_[i];
		if (!values.write) continue;
		BodyLink* link = s.bodyLink(i);
		BodyObjects& body = bodyObjects(bodies, i, link->bodyId);
		PyObject* state = body.state.ptr();
		setVector(state, n.pos, values.position);
		*quaternionValue_ = values.orientation;
		check(PyObject_SetAttr(state, n.ori, quaternion_.ptr()));
		setVector(state, n.vel, values.velocity);
		setVector(state, n.angVel, values.angularVelocity);
		if (values.vertices) {
			const VertexList& list = vertexList(values.local.size());
			for (std::size_t k = 0; k < values.local.size(); ++k) *list.values[k] = values.local[k];
			check(PyObject_SetAttr(body.shape.ptr(), n.v, list.list.ptr()));
			s.world.block(i).unsyncedStrain = 0;
		}
		link->synced = true;
		++written;
	}
	written += writeClumps(s, bodies, all);
	resend_ = false;
	return written;
}

// The clumps of concave blocks: the whole block's centroid, orientation and
// velocity (the members are written above, part by part).
int YadeSync::writeClumps(SceneLink& s, const py::object& bodies, bool all) {
	const Names& n = names();
	int written = 0;
	for (const auto& [block, clump] : s.clumps()) {
		const Block& b = s.world.block(block);
		ClumpLink& link = *s.clumpLink(block);
		if (b.fixed && !b.shaken && link.synced && !resend_ && !all) continue;
		BodyObjects& objects = clumpObjects_[block];
		if (objects.state.is_none()) objects = lookUp(bodies, clump.bodyId);
		PyObject* state = objects.state.ptr();
		setVector(state, n.pos, b.centroid);
		*quaternionValue_ = s.clumpOrientation(block);
		check(PyObject_SetAttr(state, n.ori, quaternion_.ptr()));
		setVector(state, n.vel, b.velocity.head<3>());
		setVector(state, n.angVel, b.velocity.segment<3>(3));
		link.synced = true;
		++written;
	}
	return written;
}

// Adds target - (what O.forces holds) to each block's force and torque:
// what it holds is read back when readBack (all blocks first: after an addF,
// YADE's container reads wrong until summed again), else taken from written_.
void YadeSync::addForces(const std::vector<BodyForce>& target, const py::object& forces, bool readBack) {
	if (readBack) {
		const py::object f = forces.attr("f"), t = forces.attr("t");
		for (std::size_t k = 0; k < target.size(); ++k)
			written_[k] = BodyForce{target[k].bodyId, readVector(f(target[k].bodyId)), readVector(t(target[k].bodyId))};
	}
	const py::object addF = forces.attr("addF"), addT = forces.attr("addT");
	for (std::size_t k = 0; k < target.size(); ++k) {
		const BodyForce& now = target[k];
		const py::object id(now.bodyId);
		// The container adds in floating point, so it then holds held + (now - held), which need not
		// be `now` to the last bit: written_ keeps that sum, what the probe will read.
		BodyForce& held = written_[k];
		if (held.force != now.force) {
			*vectorValue_ = now.force - held.force;
			owned(PyObject_CallFunctionObjArgs(addF.ptr(), id.ptr(), vector_.ptr(), nullptr));
			held.force += *vectorValue_;
		}
		if (held.torque != now.torque) {
			*vectorValue_ = now.torque - held.torque;
			owned(PyObject_CallFunctionObjArgs(addT.ptr(), id.ptr(), vector_.ptr(), nullptr));
			held.torque += *vectorValue_;
		}
	}
}

// What O.forces holds of a block is trusted to be what this object wrote
// last when a probe agrees: the first block believed to carry a nonzero force
// or torque (a reset of the container, by a ForceResetter or a script,
// zeroes every body at once, so it shows there), or the first block when all
// are believed zero (then a reset changed nothing). Else every block is read.
int YadeSync::writeViews(const SceneLink& s, const IntegratorSettings& settings, const py::object& forces,
                         const py::object& interactions, bool keep, const py::list& foreign) {
	const ContactViews views = contactViews(s, settings, keep);
	writeForces(views.bodies, forces);
	return writeInteractions(views.pairs, interactions, keep, foreign);
}

void YadeSync::writeForces(const std::vector<BodyForce>& target, const py::object& forces) {
	if (target.empty()) return;
	// YADE's container (OpenMP build) keeps per-thread sums: f(id, True) sums them first.
	forces.attr("f")(target.front().bodyId, true);
	bool trusted = written_.size() == target.size();
	if (trusted) {
		std::size_t probe = written_.size();
		for (std::size_t k = 0; k < written_.size(); ++k) {
			if (written_[k].bodyId != target[k].bodyId) trusted = false;
			const bool nonzero = written_[k].force != Vector3::Zero() || written_[k].torque != Vector3::Zero();
			if (nonzero && probe == written_.size()) probe = k;
		}
		if (probe == written_.size()) probe = 0;
		trusted = trusted && readVector(forces.attr("f")(written_[probe].bodyId)) == written_[probe].force &&
		          readVector(forces.attr("t")(written_[probe].bodyId)) == written_[probe].torque;
	}
	if (!trusted) written_ = std::vector<BodyForce>(target.size(), BodyForce{-1, Vector3::Zero(), Vector3::Zero()});
	bool changed = !trusted;
	for (std::size_t k = 0; k < target.size() && !changed; ++k)
		changed = target[k].force != written_[k].force || target[k].torque != written_[k].torque;
	if (!changed) return;
	addForces(target, forces, !trusted);
	if (!trusted) ++forceReadBacks_;
	forces.attr("f")(target.front().bodyId, true);  // sum again: f(id) reads the totals
}

YadeSync::PairObjects YadeSync::pairObjects(const py::object& interactions, int id1, int id2) {
	const Names& n = names();
	const py::object key = py::make_tuple(id1, id2);
	PyObject* found = PyObject_GetItem(interactions.ptr(), key.ptr());
	py::object interaction;
	if (found) {
		interaction = owned(found);
	} else if (PyErr_ExceptionMatches(PyExc_IndexError)) {
		PyErr_Clear();
		interaction = createInteraction_(id1, id2, true);  // virtual: no YADE functor runs
	} else {
		py::throw_error_already_set();
	}
	PairObjects objects{owned(PyObject_GetAttr(interaction.ptr(), n.geom)),
	                    owned(PyObject_GetAttr(interaction.ptr(), n.phys))};
	if (!PyObject_IsInstance(objects.geom.ptr(), geomClass_.ptr())) {
		objects.geom = geomClass_();
		check(PyObject_SetAttr(interaction.ptr(), n.geom, objects.geom.ptr()));
	}
	if (!PyObject_IsInstance(objects.phys.ptr(), physClass_.ptr())) {
		objects.phys = physClass_();
		check(PyObject_SetAttr(interaction.ptr(), n.phys, objects.phys.ptr()));
	}
	return objects;
}

int YadeSync::writeInteractions(const std::vector<PairView>& current, const py::object& interactions, bool keep,
                                const py::list& foreign) {
	const Names& n = names();
	std::map<std::pair<int, int>, PairObjects> kept;
	for (const PairView& p : current) {
		const std::pair<int, int> ids(p.id1, p.id2);
		auto found = pairs_.find(ids);
		const bool known = found != pairs_.end() && !found->second.geom.is_none();
		PairObjects objects = known ? found->second : pairObjects(interactions, p.id1, p.id2);
		setVector(objects.geom.ptr(), n.contactPoint, p.point);
		setVector(objects.geom.ptr(), n.normal, p.normal);
		setVector(objects.phys.ptr(), n.normalForce, p.normalForce);
		setVector(objects.phys.ptr(), n.shearForce, p.shearForce);
		setDouble(objects.phys.ptr(), n.kn, p.kn);
		setDouble(objects.phys.ptr(), n.ks, p.ks);
		setDouble(objects.phys.ptr(), n.tanPhi, p.tanPhi);
		kept.emplace_hint(kept.end(), ids, objects);
	}
	// Pairs shown before (or brought by a loaded scene) that are not current.
	std::vector<std::pair<int, int>> gone;
	for (const auto& entry : pairs_)
		if (!kept.count(entry.first)) gone.push_back(entry.first);
	for (long k = 0; k < py::len(foreign); ++k) {
		const std::pair<int, int> ids(py::extract<int>(foreign[k][0])(), py::extract<int>(foreign[k][1])());
		if (!kept.count(ids)) gone.push_back(ids);
	}
	pairs_ = std::move(kept);  // before erasing: yade_dda.hooks' erase asks this object to forget
	bool erased = false;
	for (const auto& [id1, id2] : gone) {
		if (!py::extract<bool>(interactions.attr("has")(id1, id2))()) continue;
		interactions.attr("erase")(id1, id2);  // YADE leaves a virtual interaction for a collider to remove...
		erased = true;
	}
	// ... there is none that would (no live InteractionLoop): remove them here.
	if (erased && keep) interactions.attr("eraseNonReal")();
	return static_cast<int>(pairs_.size());
}

void YadeSync::forgetBodies() {
	bodies_.clear();
	clumpObjects_.clear();
	resend_ = true;  // the new objects get everything, fixed blocks and vertices too
}

void YadeSync::forgetInteractions() { pairs_.clear(); }

// The pair stays listed, without objects: YADE's erase leaves a virtual
// interaction, which the next write erases if the pair is not current.
void YadeSync::forgetInteraction(int id1, int id2) {
	auto found = pairs_.find(std::minmax(id1, id2));
	if (found != pairs_.end()) found->second = PairObjects();
}

YadeSync::Counters YadeSync::counters() const {
	int bodies = 0;
	for (const BodyObjects& b : bodies_) bodies += !b.state.is_none();
	for (const auto& entry : clumpObjects_) bodies += !entry.second.state.is_none();
	return Counters{bodies, static_cast<int>(pairs_.size()), forceReadBacks_};
}

}  // namespace dda
