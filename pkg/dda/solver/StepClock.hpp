// The step's phase timings (StepStatistics' time* and cpu* fields) and when
// its per-block loops run threaded.
#pragma once

#include <chrono>
#include <ctime>

namespace dda {

using Clock = std::chrono::steady_clock;

// Per-block loops run in parallel only from this many blocks (or pairs, or
// components) on. Waking an OpenMP team costs tens of microseconds on idle
// cores, and when another process holds a core each barrier can wait a whole
// scheduler slice (milliseconds): a 100-block pile took 44 ms per step with 2
// threads on a loaded 2-core machine, 0.5 ms with one. A block's own work is
// about a microsecond, so below ~1000 blocks threads cannot pay.
constexpr int kMinBlocksForThreads = 1024;
// The same for per-contact loops: a contact's own work is a few tenths of a
// microsecond.
constexpr int kMinContactsForThreads = 2048;
// The same for the narrow phase's candidate pairs: a pair's own work (its
// tests, sub-contacts and contacts' set-up) is 3 to 5 microseconds, so 256
// pairs are about the millisecond of work 1024 blocks are.
constexpr int kMinPairsForThreads = 256;

inline double secondsSince(Clock::time_point start) {
	return std::chrono::duration<double>(Clock::now() - start).count();
}
// CPU time of the whole process, all threads [s] (not wall time: a busy or
// virtualised machine's waits are not counted).
inline double processCpuSeconds() {
	timespec now{};
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
	return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

}  // namespace dda
