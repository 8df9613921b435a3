// What fuzz_kernels.cpp did, for the driver's summary (libFuzzer ignores it).
#pragma once

#include <cstddef>
#include <cstdint>

struct FuzzCounters {
	long inputs = 0;
	long polyhedraBuilt = 0;     // valid blocks built and checked (mode 0)
	long polyhedraRejected = 0;  // point sets rejected with InputError
	long pairsInContact = 0;     // detectPairContacts calls that found the pair within d0 (mode 1)
	long subContacts = 0;        // sub-contacts whose equations were exercised
	long steps = 0;              // World::step calls that returned (mode 2)
	long stepsRefused = 0;       // World::step calls that raised the core's own clear error
};

const FuzzCounters& fuzzCounters();

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);
