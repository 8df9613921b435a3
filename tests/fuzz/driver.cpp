// A plain driver for a libFuzzer target, built with g++ (no clang needed):
// runs every file of the seed corpus, then a structured sweep (every mode and
// family byte with a pseudo-random tail), then pseudo-random inputs and
// mutations of the corpus, deterministically from --seed, until --seconds or
// --iterations runs out. Used by ctest (bounded) and by `make fuzz`.
//
//   fuzz_kernels_driver [--seconds S] [--iterations N] [--seed K] [--max-len L]
//                       [--crash-dir DIR] [corpus files or directories...]
//
// A finding aborts (or crashes) inside the target; a signal handler first
// writes the input to DIR/crash-<iteration>.bin (default: the working
// directory) and prints it in hex. Reproduce with
//   fuzz_kernels_driver --iterations 0 crash-<iteration>.bin
// (or the libFuzzer build: fuzz_kernels crash-<iteration>.bin).
#include "fuzz_kernels.hpp"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <dirent.h>
#include <fcntl.h>
#include <random>
#include <string>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

namespace {

// The input being run, for the signal handler (which may only use
// async-signal-safe calls: open, write, close).
std::vector<std::uint8_t> current;
char crashPath[4096] = "crash.bin";

void writeHexDigit(int fd, unsigned v) {
	const char c = "0123456789abcdef"[v & 15];
	(void)!write(fd, &c, 1);
}

void onSignal(int signal) {
	const int fd = open(crashPath, O_WRONLY | O_CREAT | O_TRUNC, 0644);
	if (fd >= 0) {
		(void)!write(fd, current.data(), current.size());
		close(fd);
	}
	const char head[] = "\nfuzz driver: the input was written to ";
	(void)!write(2, head, sizeof head - 1);
	(void)!write(2, crashPath, std::strlen(crashPath));
	const char hex[] = "\ninput (hex): ";
	(void)!write(2, hex, sizeof hex - 1);
	for (std::uint8_t b : current) {
		writeHexDigit(2, b >> 4);
		writeHexDigit(2, b);
	}
	(void)!write(2, "\n", 1);
	std::signal(signal, SIG_DFL);
	std::raise(signal);
}

std::vector<std::uint8_t> readFile(const std::string& path) {
	std::vector<std::uint8_t> data;
	if (FILE* f = std::fopen(path.c_str(), "rb")) {
		std::uint8_t buffer[4096];
		std::size_t n;
		while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) data.insert(data.end(), buffer, buffer + n);
		std::fclose(f);
	} else {
		std::fprintf(stderr, "fuzz driver: cannot read %s\n", path.c_str());
		std::exit(2);
	}
	return data;
}

void collect(const std::string& path, std::vector<std::vector<std::uint8_t>>& corpus) {
	struct stat info;
	if (stat(path.c_str(), &info) != 0) {
		std::fprintf(stderr, "fuzz driver: no such file or directory: %s\n", path.c_str());
		std::exit(2);
	}
	if (!S_ISDIR(info.st_mode)) {
		corpus.push_back(readFile(path));
		return;
	}
	std::vector<std::string> names;
	if (DIR* dir = opendir(path.c_str())) {
		while (dirent* entry = readdir(dir))
			if (entry->d_name[0] != '.') names.push_back(path + "/" + entry->d_name);
		closedir(dir);
	}
	std::sort(names.begin(), names.end());  // deterministic order
	for (const std::string& name : names) collect(name, corpus);
}

void run(const std::vector<std::uint8_t>& input, long iteration, const std::string& crashDir) {
	current = input;
	std::snprintf(crashPath, sizeof crashPath, "%s/crash-%ld.bin", crashDir.c_str(), iteration);
	LLVMFuzzerTestOneInput(current.data(), current.size());
}

void mutate(std::vector<std::uint8_t>& data, std::mt19937_64& rng, std::size_t maxLength) {
	const int edits = 1 + static_cast<int>(rng() % 4);
	for (int k = 0; k < edits; ++k) {
		switch (rng() % 5) {
		case 0:  // flip a bit
			if (!data.empty()) data[rng() % data.size()] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
			break;
		case 1:  // a random byte
			if (!data.empty()) data[rng() % data.size()] = static_cast<std::uint8_t>(rng());
			break;
		case 2:  // insert bytes
			if (data.size() < maxLength) data.insert(data.begin() + rng() % (data.size() + 1), static_cast<std::uint8_t>(rng()));
			break;
		case 3:  // truncate
			if (!data.empty()) data.resize(rng() % data.size());
			break;
		default:  // an interesting byte (0, 1, 0x7f, 0x80, 0xff)
			if (!data.empty()) {
				static const std::uint8_t interesting[] = {0, 1, 0x7f, 0x80, 0xff};
				data[rng() % data.size()] = interesting[rng() % 5];
			}
			break;
		}
	}
}

}  // namespace

int main(int argc, char** argv) {
	double seconds = 10;
	long iterations = -1;  // -1: until the time runs out
	unsigned long seed = 1;
	std::size_t maxLength = 256;
	std::string crashDir = ".";
	std::vector<std::vector<std::uint8_t>> corpus;
	for (int k = 1; k < argc; ++k) {
		const std::string arg = argv[k];
		auto value = [&](const char* name) -> std::string {
			if (k + 1 >= argc) {
				std::fprintf(stderr, "fuzz driver: %s needs a value\n", name);
				std::exit(2);
			}
			return argv[++k];
		};
		if (arg == "--seconds") seconds = std::stod(value("--seconds"));
		else if (arg == "--iterations") iterations = std::stol(value("--iterations"));
		else if (arg == "--seed") seed = std::stoul(value("--seed"));
		else if (arg == "--max-len") maxLength = std::stoul(value("--max-len"));
		else if (arg == "--crash-dir") crashDir = value("--crash-dir");
		else if (arg == "--help" || arg == "-h") {
			std::printf("usage: %s [--seconds S] [--iterations N] [--seed K] [--max-len L] [--crash-dir DIR] "
			            "[corpus files or directories...]\n", argv[0]);
			return 0;
		} else collect(arg, corpus);
	}
	for (int s : {SIGSEGV, SIGABRT, SIGFPE, SIGBUS, SIGILL}) std::signal(s, onSignal);

	const auto start = std::chrono::steady_clock::now();
	auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
	long iteration = 0;
	for (const auto& input : corpus) run(input, iteration++, crashDir);
	const long corpusRuns = iteration;

	std::mt19937_64 rng(seed);
	auto randomTail = [&](std::vector<std::uint8_t>& data, std::size_t length) {
		while (data.size() < length) data.push_back(static_cast<std::uint8_t>(rng()));
	};
	auto more = [&] { return iterations < 0 ? elapsed() < seconds : iteration - corpusRuns < iterations; };
	// Structured sweep: every (mode, family/placement) pair of leading bytes.
	for (int mode = 0; mode < 3 && more(); ++mode)
		for (int family = 0; family < 10 && more(); ++family) {
			std::vector<std::uint8_t> data{static_cast<std::uint8_t>(mode), static_cast<std::uint8_t>(family)};
			randomTail(data, 1 + rng() % maxLength);
			run(data, iteration++, crashDir);
		}
	while (more()) {
		std::vector<std::uint8_t> data;
		if (!corpus.empty() && rng() % 2 == 0) {
			data = corpus[rng() % corpus.size()];
			mutate(data, rng, maxLength);
		} else {
			randomTail(data, rng() % (maxLength + 1));
		}
		run(data, iteration++, crashDir);
	}
	const FuzzCounters& c = fuzzCounters();
	std::printf("fuzz driver: %ld inputs (%ld from the corpus) in %.1f s, seed %lu: %ld polyhedra built and checked, "
	            "%ld rejected; %ld pairs in contact, %ld sub-contacts' equations; %ld steps, %ld refused with the "
	            "core's own error; no finding\n",
	            c.inputs, corpusRuns, elapsed(), seed, c.polyhedraBuilt, c.polyhedraRejected, c.pairsInContact,
	            c.subContacts, c.steps, c.stepsRefused);
	return 0;
}
