// The narrow phase alone: the candidate pairs of MSC on a slender deposit, each block's
// planes built once (BlockPlanes), then every pair through detectPairContacts, repeated; prints the
// best of the repetitions per candidate pair [us] (caches warm, no contact store, no contact set-up),
// after one World::step's own narrow-phase time. A measuring aid for changes to pkg/dda/contact, not
// built by CMake. Blocks are read from a text file: the block count, then 24 coordinates [m] per line
// (8 corners), e.g. bench/colliders.py's deposit:
//   /usr/bin/python3 -c "import sys,numpy as np; sys.path.insert(0,'bench'); import colliders as c; \
//     c.ensureSlender('bench/out', 1000, 1); v=np.load(c.slenderFile('bench/out', 1000, 1))['vertices']; \
//     open('/tmp/slender_1000.txt','w').write('%d\n' % len(v) + ''.join(' '.join(map(repr, b.ravel().tolist())) + '\n' for b in v))"
//   g++ -O2 -DNDEBUG -frounding-math -fopenmp -std=gnu++17 -DCGAL_USE_GMPXX=1 -Ipkg -isystem /usr/include/eigen3 \
//     bench/narrow_phase.cpp build/libdda_core.a -lgmpxx -lmpfr -lgmp -o /tmp/narrow_phase
//   /tmp/narrow_phase /tmp/slender_1000.txt 30      # repetitions
// Run it alternately with a build of the code before a change (its own libdda_core.a): single runs
// differ by a few per cent.
#include "dda/collider/ColliderFactory.hpp"
#include "dda/collider/MSCCollider.hpp"
#include "dda/contact/PairDetection.hpp"
#include "dda/solver/ContactDetection.hpp"
#include "dda/solver/World.hpp"
#include <chrono>
#include <cstdio>
#include <fstream>
using namespace dda;
static double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }
int main(int argc, char** argv) {
	std::ifstream in(argv[1]);
	const int reps = argc > 2 ? atoi(argv[2]) : 5;
	int n; in >> n;
	World world;
	Material m; m.young = 1e9; m.poisson = 0.25; m.density = 2600; m.frictionAngle = 0.5235987755982988;
	for (int b = 0; b < n; ++b) {
		std::vector<Vector3> p(8);
		for (auto& x : p) in >> x.x() >> x.y() >> x.z();
		world.addBlock(p, m, false);
	}
	world.setCollider(makeCollider("MSC"));
	IntegratorSettings s;
	s.maxTimeStep = 1e-3; s.maxDisplacement = 0.004; s.contactDistance = 0.01; s.gravity = Vector3(0, 0, -9.81);
	s.threads = 1; s.reuseCandidatePairs = false;
	for (int k = 0; k < 1; ++k) {
		world.step(s);
		const auto& st = world.lastStep();
		printf("step: narrow %.2f ms, %ld candidates, %.3f us/candidate\n", 1e3 * st.timeNarrowPhase, st.candidatePairs,
		       1e6 * st.timeNarrowPhase / st.candidatePairs);
	}
	std::vector<Block> blocks;
	for (int b = 0; b < world.blockCount(); ++b) blocks.push_back(world.block(b));
	MSCCollider msc;
	std::vector<std::pair<int, int>> pairs;
	BroadPhaseStatistics bs;
	msc.findPairs(blocks, 0.01, pairs, bs);
	std::vector<BlockPlanes> planes(blocks.size());
	std::vector<double> diag(blocks.size());
	double tp = 1e9;
	for (int r = 0; r < reps; ++r) {
		const double t0 = now();
		for (std::size_t b = 0; b < blocks.size(); ++b) planes[b].compute(*blocks[b].shape, blocks[b].vertices);
		tp = std::min(tp, now() - t0);
	}
	for (std::size_t b = 0; b < blocks.size(); ++b) diag[b] = boundingDiagonal(blocks[b]);
	PairContacts out;
	long found = 0, subs = 0;
	NarrowPhaseWork work;
	double tq = 1e9;
	for (int r = 0; r < reps; ++r) {
		const double t0 = now();
		for (std::size_t q = 0; q < pairs.size(); ++q) {
			const auto [a, b] = pairs[q];
			const DetectionSettings d = pairDetectionSettings(diag[a], diag[b], 0.01, 0.004);
			const bool f = detectPairContacts(
			    BlockGeometry{blocks[a].shape.get(), &blocks[a].vertices, interiorPoint(blocks[a]), nullptr, &planes[a]},
			    BlockGeometry{blocks[b].shape.get(), &blocks[b].vertices, interiorPoint(blocks[b]), nullptr, &planes[b]}, d,
			    out, EntranceFeature{}, msc.linked(static_cast<int>(q)), &work);
			found += f;
			if (f) subs += out.contacts.size();
		}
		tq = std::min(tq, now() - t0);
	}
	printf("alone: %zu pairs, found %ld, sub-contacts %ld; planes %.2f ms (%.3f us/block, %.3f us/candidate); pairs %.2f ms (%.3f us/candidate)\n",
	       pairs.size(), found / reps, subs / reps, 1e3 * tp, 1e6 * tp / blocks.size(), 1e6 * tp / pairs.size(), 1e3 * tq,
	       1e6 * tq / pairs.size());
}
