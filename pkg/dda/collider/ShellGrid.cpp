// Subspaces: cubic cells as wide as the mean shell's largest side (at least
// 1/kMaxCellsPerAxis of the domain). A shell enters every cell it overlaps;
// one spanning more than kMaxCellsPerShell cells (a floor, a block much
// larger than the rest) is compared with every shell instead. Two shells
// are compared in one cell only: the cell of the lower corner of their
// boxes' intersection. Layout::of is monotone in each coordinate, so that
// cell is the componentwise max of the two shells' lowest cells, and lies in
// both shells' ranges when the boxes meet (the test is on the integer ranges
// computed once per shell).
#include "ShellGrid.hpp"

#include "dda/core/CapacityBytes.hpp"

#include <algorithm>
#include <array>
#include <limits>

namespace dda::msc {

namespace {

// Grid entries ahead whose shell's box is prefetched while cells are scanned.
constexpr std::size_t kPrefetchEntries = 24;

}  // namespace

// One search's comparisons. Per shell its block's fixed flag is read from
// shellFixed (filled as boxes are updated: the blocks themselves are large
// and far apart). Two shells are a test when their blocks differ and are not
// both fixed, a shell pair when their boxes meet too. The conditions are
// evaluated together, without a branch each (they are unpredictable and the
// tests cheap).
class ShellGrid::Scan {
public:
	Scan(ShellGrid& grid, const std::vector<Eigen::AlignedBox3d>& boxes, const std::vector<int>& shellBlock,
	     const std::vector<char>& shellFixed, std::vector<ItemPair>& out, std::size_t entries)
	    : grid_(grid), boxes_(boxes), shellBlock_(shellBlock), shellFixed_(shellFixed), out_(out), entries_(entries) {}

	// An oversize shell s against shell t.
	void compareShells(int s, int t) {
		const int a = shellBlock_[s], b = shellBlock_[t];
		const bool pair = (a != b) & !(static_cast<bool>(shellFixed_[s]) & static_cast<bool>(shellFixed_[t]));
		const Vector3 &lowS = boxes_[s].min(), &highS = boxes_[s].max();
		const Vector3 &lowT = boxes_[t].min(), &highT = boxes_[t].max();
		const bool meet = (lowS.x() <= highT.x()) & (lowT.x() <= highS.x()) & (lowS.y() <= highT.y()) &
		                  (lowT.y() <= highS.y()) & (lowS.z() <= highT.z()) & (lowT.z() <= highS.z());
		tests_ += pair;
		if (pair & meet) pushWithHeadroom(out_, a < b ? ItemPair{s, t} : ItemPair{t, s});
	}
	// The pairs of the cell whose entries are cellShells_[first, last).
	void scanCell(std::size_t first, std::size_t last);
	long tests() const { return tests_; }

private:
	// Fetches the boxes, blocks and fixed flags of the entries up to
	// kPrefetchEntries past `last`.
	void prefetchUpTo(std::size_t last);
	// As compareShells, on the copies.
	[[gnu::always_inline]] void compare(const CellEntry& e, const CellEntry& f, long& cellTests) {
		const bool test = (e.block != f.block) & !(e.fixed & f.fixed);
		const bool meet = (e.low.x() <= f.high.x()) & (f.low.x() <= e.high.x()) & (e.low.y() <= f.high.y()) &
		                  (f.low.y() <= e.high.y()) & (e.low.z() <= f.high.z()) & (f.low.z() <= e.high.z());
		cellTests += test;
		if (test & meet) pushWithHeadroom(out_, e.block < f.block ? ItemPair{e.shell, f.shell} : ItemPair{f.shell, e.shell});
	}

	ShellGrid& grid_;
	const std::vector<Eigen::AlignedBox3d>& boxes_;
	const std::vector<int>& shellBlock_;
	const std::vector<char>& shellFixed_;
	std::vector<ItemPair>& out_;
	std::size_t entries_;
	std::size_t prefetched_ = 0;  // the entries fetched
	long tests_ = 0;
};

void ShellGrid::Scan::prefetchUpTo(std::size_t last) {
	for (const std::size_t ahead = std::min(entries_, last + kPrefetchEntries); prefetched_ < ahead; ++prefetched_) {
		const std::uint32_t s = grid_.cellShells_[prefetched_] >> 3;
		__builtin_prefetch(&boxes_[s]);
		__builtin_prefetch(reinterpret_cast<const char*>(&boxes_[s] + 1) - 1);
		__builtin_prefetch(&shellBlock_[s]);
		__builtin_prefetch(&shellFixed_[s]);
	}
}

// Each entry is a shell (entry >> 3) and, in bits 0-2, the axes along which
// the cell is the shell's lowest. A pair is compared in the cell of the max
// of its lowest cells, which is the cell where, along every axis, one of the
// two begins: (bits of s | bits of t) == 7. About half of the pairs of a
// cell are not its own; in a cell of at most 64 entries each entry is
// compared only with the later ones whose bits complete its own, found as a
// bit mask. The entries are first copied with their boxes, blocks and fixed
// flags into cellScratch_, each box read once per cell rather than once per
// pair. Cells are scanned in the order of their entries, whose shells lie
// anywhere in the flat arrays: the boxes, blocks and fixed flags of the next
// kPrefetchEntries entries are fetched ahead.
void ShellGrid::Scan::scanCell(std::size_t first, std::size_t last) {
	prefetchUpTo(last);
	const std::size_t count = last - first;
	if (count > grid_.cellScratch_.size()) resizeWithHeadroom(grid_.cellScratch_, count);
	CellEntry* entry = grid_.cellScratch_.data();
	for (std::size_t p = 0; p < count; ++p) {
		const std::uint32_t packed = grid_.cellShells_[first + p];
		const int s = static_cast<int>(packed >> 3);
		CellEntry& e = entry[p];
		e.low = boxes_[s].min();
		e.high = boxes_[s].max();
		e.shell = s;
		e.block = shellBlock_[s];
		e.fixed = shellFixed_[s] != 0;
		e.bits = static_cast<std::uint8_t>(packed & 7);
	}
	long cellTests = 0;
	if (count <= 64) {
		// with[m]: the entries whose bits contain m (entries with bits m,
		// then summed over supersets, one axis at a time).
		std::uint64_t with[8] = {};
		for (std::size_t p = 0; p < count; ++p) with[entry[p].bits] |= std::uint64_t{1} << p;
		for (int m = 0; m < 8; m += 2) with[m] |= with[m + 1];
		for (int m : {0, 1, 4, 5}) with[m] |= with[m + 2];
		for (int m = 0; m < 4; ++m) with[m] |= with[m + 4];
		for (std::size_t p = 0; p + 1 < count; ++p) {
			const CellEntry e = entry[p];
			for (std::uint64_t later = with[~e.bits & 7] & ~std::uint64_t{0} << (p + 1); later; later &= later - 1)
				compare(e, entry[__builtin_ctzll(later)], cellTests);
		}
	} else {
		for (std::size_t p = 0; p < count; ++p)
			for (std::size_t q = p + 1; q < count; ++q)
				if ((entry[p].bits | entry[q].bits) == 7) compare(entry[p], entry[q], cellTests);
	}
	tests_ += cellTests;
}

ShellGrid::Layout ShellGrid::layoutFor(const std::vector<Eigen::AlignedBox3d>& boxes) {
	Eigen::AlignedBox3d domain;
	double sideSum = 0;
	for (const Eigen::AlignedBox3d& box : boxes) {
		domain.extend(box);
		sideSum += box.sizes().maxCoeff();
	}
	Layout grid;
	grid.origin = domain.min();
	grid.cell = std::max(sideSum / static_cast<int>(boxes.size()), domain.sizes().maxCoeff() / kMaxCellsPerAxis);
	grid.dims = grid.of(domain.max()).cast<long>() + 1;
	return grid;
}

std::size_t ShellGrid::spanCells(const std::vector<Eigen::AlignedBox3d>& boxes, const Layout& grid) {
	const int shellTotal = static_cast<int>(boxes.size());
	resizeWithHeadroom(cellLow_, shellTotal);
	resizeWithHeadroom(cellSpan_, shellTotal);
	oversize_.clear();
	std::size_t entries = 0;
	for (int s = 0; s < shellTotal; ++s) {
		cellLow_[s] = grid.of(boxes[s].min());
		const Cell extra = grid.of(boxes[s].max()) - cellLow_[s];
		const long span = (extra + 1).cast<long>().prod();
		if (span > kMaxCellsPerShell) {
			oversize_.push_back(s);
			cellSpan_[s] = CellSpan{0, 0, 0, true};
		} else {
			cellSpan_[s] = CellSpan{static_cast<std::uint8_t>(extra.x()), static_cast<std::uint8_t>(extra.y()),
			                        static_cast<std::uint8_t>(extra.z()), false};
			entries += static_cast<std::size_t>(span);
		}
	}
	return entries;
}

template <class Visit>
void ShellGrid::forEachCellOf(int s, const std::array<std::uint64_t, 3>& stride, const Visit& visit) const {
	const Cell& lo = cellLow_[s];
	const int spanX = cellSpan_[s].x, spanY = cellSpan_[s].y, spanZ = cellSpan_[s].z;
	const std::uint64_t base = lo.x() * stride[0] + lo.y() * stride[1] + lo.z();
	const std::uint32_t shell = static_cast<std::uint32_t>(s) << 3;
	for (int i = 0; i <= spanX; ++i)
		for (int j = 0; j <= spanY; ++j) {
			const std::uint64_t row = base + i * stride[0] + j * stride[1];
			const std::uint32_t bits = shell | (i == 0) | (j == 0) << 1;
			for (int k = 0; k <= spanZ; ++k) visit(row + k, bits | (k == 0) << 2);
		}
}

void ShellGrid::scanDense(Scan& scan, std::size_t cells, const std::array<std::uint64_t, 3>& stride) {
	// Counting sort: count per cell, prefix sums (cellStart_[c + 1] = end
	// of cell c), then shells placed from the last down, so each cell's
	// shells ascend and cellStart_[c + 1] ends at the cell's first entry.
	const int shellTotal = static_cast<int>(cellSpan_.size());
	const std::size_t entries = cellShells_.size();
	resizeWithHeadroom(cellStart_, cells + 2);
	std::fill(cellStart_.begin(), cellStart_.end(), 0);
	for (int s = 0; s < shellTotal; ++s)
		if (!cellSpan_[s].oversize) forEachCellOf(s, stride, [&](std::uint64_t c, std::uint32_t) { ++cellStart_[c + 1]; });
	for (std::size_t c = 0; c < cells; ++c) cellStart_[c + 1] += cellStart_[c];
	for (int s = shellTotal - 1; s >= 0; --s)
		if (!cellSpan_[s].oversize)
			forEachCellOf(s, stride, [&](std::uint64_t c, std::uint32_t e) { cellShells_[--cellStart_[c + 1]] = e; });
	// Now cellStart_[c + 1] is the start of cell c; cell c is [cellStart_[c + 1], cellStart_[c + 2]).
	cellStart_[cells + 1] = static_cast<std::uint32_t>(entries);
	for (std::size_t c = 0; c < cells; ++c)
		if (cellStart_[c + 2] - cellStart_[c + 1] > 1) scan.scanCell(cellStart_[c + 1], cellStart_[c + 2]);
}

void ShellGrid::scanSparse(Scan& scan, const std::array<std::uint64_t, 3>& stride) {
	// By comparison on (cell key, entry): the entries of a cell ascend by shell.
	const int shellTotal = static_cast<int>(cellSpan_.size());
	const std::size_t entries = cellShells_.size();
	cellEntries_.clear();
	cellEntries_.reserve(entries);
	for (int s = 0; s < shellTotal; ++s)
		if (!cellSpan_[s].oversize)
			forEachCellOf(s, stride, [&](std::uint64_t c, std::uint32_t e) { cellEntries_.emplace_back(c, e); });
	std::sort(cellEntries_.begin(), cellEntries_.end());
	for (std::size_t p = 0; p < entries; ++p) cellShells_[p] = cellEntries_[p].second;
	for (std::size_t first = 0; first < entries;) {
		std::size_t last = first + 1;
		while (last < entries && cellEntries_[last].first == cellEntries_[first].first) ++last;
		scan.scanCell(first, last);
		first = last;
	}
}

long ShellGrid::search(const std::vector<Eigen::AlignedBox3d>& boxes, const std::vector<int>& shellBlock,
                       const std::vector<char>& shellFixed, std::vector<ItemPair>& out) {
	out.clear();
	const int shellTotal = static_cast<int>(boxes.size());
	const Layout grid = layoutFor(boxes);
	const std::size_t entries = spanCells(boxes, grid);
	// Cell keys: the cell's index in the domain's grid when the grid has at
	// most kDenseCellsPerEntry x the entries (then sorted by counting), else
	// the three coordinates packed in 21 bits each (sorted by comparison).
	const Eigen::Array<long, 3, 1>& dims = grid.dims;
	const double denseCells = static_cast<double>(dims.x()) * static_cast<double>(dims.y()) * static_cast<double>(dims.z());
	dense_ = denseCells <= kDenseCellsPerEntry * static_cast<double>(entries) + kDenseCellsFloor &&
	         entries < std::numeric_limits<std::uint32_t>::max();
	// A cell's key is linear in its coordinates: stride x coordinate, summed.
	const std::array<std::uint64_t, 3> stride =
	    dense_ ? std::array<std::uint64_t, 3>{static_cast<std::uint64_t>(dims.y() * dims.z()), static_cast<std::uint64_t>(dims.z()), 1}
	           : std::array<std::uint64_t, 3>{std::uint64_t{1} << 42, std::uint64_t{1} << 21, 1};
	Scan scan(*this, boxes, shellBlock, shellFixed, out, entries);
	resizeWithHeadroom(cellShells_, entries);
	if (dense_) scanDense(scan, static_cast<std::size_t>(denseCells), stride);
	else scanSparse(scan, stride);
	// An oversize shell is compared with every shell.
	for (int s : oversize_)
		for (int t = 0; t < shellTotal; ++t)
			if (t != s && (!cellSpan_[t].oversize || s < t)) scan.compareShells(s, t);
	return scan.tests();
}

std::size_t ShellGrid::memoryBytes() const {
	return capacityBytes(cellLow_) + capacityBytes(cellSpan_) + capacityBytes(cellEntries_) + capacityBytes(cellShells_) +
	       capacityBytes(cellStart_) + capacityBytes(cellScratch_) + capacityBytes(oversize_);
}

}  // namespace dda::msc
