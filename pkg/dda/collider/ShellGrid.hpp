// MSCCollider's subspaces (MSCCollider.hpp): shells' boxes binned in a
// uniform grid of cubic cells as wide as the mean shell, and compared within
// cells, each pair in one cell only (ShellGrid.cpp explains which). Cells are
// keyed by their index and counted into place when the grid is dense enough,
// else by packed coordinates and a comparison sort (a far-flung scene); a
// shell spanning more than kMaxCellsPerShell cells (a floor) is compared with
// every shell instead.
#pragma once

#include "PairCache.hpp"

#include "dda/core/Types.hpp"

#include <Eigen/Geometry>

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace dda::msc {

// Subspaces: at most this many cells per axis (cell keys are 3 x 21 bits)
// and a shell spanning more cells than kMaxCellsPerShell is compared with
// every shell rather than entered in each.
constexpr long kMaxCellsPerAxis = 1 << 20;
constexpr long kMaxCellsPerShell = 64;
// The grid's cells are keyed by their index (and sorted by counting) when
// there are at most this x the entries plus kDenseCellsFloor cells.
constexpr double kDenseCellsPerEntry = 4;
constexpr double kDenseCellsFloor = 4096;

class ShellGrid {
public:
	// Every shell pair (different blocks, not both fixed as shellFixed says)
	// whose `boxes` meet, into `out` (unsorted; first the shell of the lower
	// block); returns the box comparisons made.
	long search(const std::vector<Eigen::AlignedBox3d>& boxes, const std::vector<int>& shellBlock,
	            const std::vector<char>& shellFixed, std::vector<ItemPair>& out);
	// Whether the last search keyed its cells densely (counting sort) or by
	// packed coordinates (a sparse domain).
	bool dense() const { return dense_; }
	std::size_t memoryBytes() const;

private:
	class Scan;
	using Cell = Eigen::Array<int, 3, 1>;  // a subspace's integer coordinates
	// The grid of one search: its lower corner, cell width [m] and cells per axis.
	struct Layout {
		Vector3 origin;
		double cell;
		Eigen::Array<long, 3, 1> dims;
		// The cell holding x (x >= origin: the domain holds every box, so
		// truncation is the floor).
		Cell of(const Vector3& x) const {
			return ((x - origin) / cell).array().cast<long>().min(kMaxCellsPerAxis - 1).max(0).cast<int>().eval();
		}
	};
	// Per flat shell the cells its box spans: from cellLow_ on, span more per
	// axis (at most kMaxCellsPerShell - 1), unless it is oversize.
	struct CellSpan {
		std::uint8_t x, y, z;
		bool oversize;
	};
	// A cell's entry as its pairs are compared.
	struct CellEntry {
		Vector3 low, high;  // the shell's box
		int shell, block;
		bool fixed;
		std::uint8_t bits;  // bits 0-2 of its entry
	};

	static Layout layoutFor(const std::vector<Eigen::AlignedBox3d>& boxes);
	// Fills cellLow_, cellSpan_ and oversize_; returns the entries (shell, cell).
	std::size_t spanCells(const std::vector<Eigen::AlignedBox3d>& boxes, const Layout& grid);
	// Visits the cells of shell s with its entry there.
	template <class Visit>
	void forEachCellOf(int s, const std::array<std::uint64_t, 3>& stride, const Visit& visit) const;
	// The entries sorted by cell, and each cell with two or more scanned.
	void scanDense(Scan& scan, std::size_t cells, const std::array<std::uint64_t, 3>& stride);
	void scanSparse(Scan& scan, const std::array<std::uint64_t, 3>& stride);

	std::vector<Cell> cellLow_;
	std::vector<CellSpan> cellSpan_;
	std::vector<std::pair<std::uint64_t, std::uint32_t>> cellEntries_;  // sparse keys: (cell key, entry), sorted
	// Every cell's entries, cell after cell: shell << 3 | the axes along
	// which the cell is the shell's lowest (bit 0: x, 1: y, 2: z).
	std::vector<std::uint32_t> cellShells_;
	std::vector<CellEntry> cellScratch_;    // one cell's entries
	std::vector<std::uint32_t> cellStart_;  // dense keys: where each cell's shells start
	bool dense_ = false;
	std::vector<int> oversize_;  // shells compared with every shell
};

}  // namespace dda::msc
