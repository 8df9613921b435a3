#include "BlockCholesky.hpp"

#include "BlockKernels.hpp"
#include "dda/core/CapacityBytes.hpp"

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>

#include <algorithm>

namespace dda {

namespace {

// The entry of row `row` in column `column`'s sorted rows.
int entryOf(const std::vector<int>& columnStart, const std::vector<int>& rows, int column, int row) {
	const auto first = rows.begin() + columnStart[column], last = rows.begin() + columnStart[column + 1];
	return static_cast<int>(std::lower_bound(first, last, row) - rows.begin());
}

// The strain rows and columns of a rigid block replaced by the identity's.
void rigidDiagonal(Matrix12& m) {
	m.block<6, 6>(6, 0).setZero();
	m.block<6, 6>(0, 6).setZero();
	m.block<6, 6>(6, 6).setIdentity();
}

}  // namespace

void BlockCholesky::analyse(int blocks, const std::vector<std::pair<int, int>>& links) {
	// Fill-reducing order of the block graph (AMD; the diagonal keeps every block in it).
	std::vector<Eigen::Triplet<double>> pattern;
	pattern.reserve(blocks + 2 * links.size());
	for (int k = 0; k < blocks; ++k) pattern.emplace_back(k, k, 1.0);
	for (auto [lo, hi] : links) {
		pattern.emplace_back(lo, hi, 1.0);
		pattern.emplace_back(hi, lo, 1.0);
	}
	Eigen::SparseMatrix<double> graph(blocks, blocks);
	graph.setFromTriplets(pattern.begin(), pattern.end());
	Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> permutation;
	Eigen::AMDOrdering<int>()(graph, permutation);
	inverse_.assign(permutation.indices().data(), permutation.indices().data() + blocks);

	// Symbolic factorisation: column j's rows are its links below the
	// diagonal and its children's rows other than j (a child c of j: j is the
	// first row of column c).
	std::vector<std::vector<int>> below(blocks), children(blocks);
	for (auto [lo, hi] : links) {
		const int a = inverse_[lo], b = inverse_[hi];
		below[std::min(a, b)].push_back(std::max(a, b));
	}
	columnStart_.assign(blocks + 1, 0);
	rows_.clear();
	std::vector<int> column;
	for (int j = 0; j < blocks; ++j) {
		column = below[j];
		for (int c : children[j])
			for (int p = columnStart_[c]; p < columnStart_[c + 1]; ++p)
				if (rows_[p] != j) column.push_back(rows_[p]);
		std::sort(column.begin(), column.end());
		column.erase(std::unique(column.begin(), column.end()), column.end());
		rows_.insert(rows_.end(), column.begin(), column.end());
		columnStart_[j + 1] = static_cast<int>(rows_.size());
		if (!column.empty()) children[column.front()].push_back(j);
	}
	linkTarget_.clear();
	for (auto [lo, hi] : links) {
		const int a = inverse_[lo], b = inverse_[hi];
		// L's block (row i, column j), i > j, is K[block of i][block of j]:
		// K[lo][hi] transposed when hi comes later (b > a, target >= 0), else
		// K[lo][hi] itself (target -1 - entry).
		const int entry = entryOf(columnStart_, rows_, std::min(a, b), std::max(a, b));
		linkTarget_.push_back(b > a ? entry : -1 - entry);
	}
	updateTarget_.clear();
	for (int j = 0; j < blocks; ++j)
		for (int p = columnStart_[j]; p < columnStart_[j + 1]; ++p)
			for (int q = columnStart_[j]; q < p; ++q)
				updateTarget_.push_back(entryOf(columnStart_, rows_, rows_[q], rows_[p]));
	factor_.resize(rows_.size());
	diagonal_.resize(blocks);
	pivots_.resize(blocks);
	sizes_.resize(blocks);
}

bool BlockCholesky::factorize(const Matrix12* diagonal, const Matrix12* offDiagonal, const int* sizes) {
	const int blocks = this->blocks();
	for (Matrix12& m : factor_) m.setZero();
	for (int k = 0; k < blocks; ++k) {
		const int j = inverse_[k];
		sizes_[j] = sizes[k];
		diagonal_[j] = diagonal[k];
		if (sizes[k] != kBlockDofs) rigidDiagonal(diagonal_[j]);
	}
	for (std::size_t l = 0; l < linkTarget_.size(); ++l) {
		const int target = linkTarget_[l];
		Matrix12& m = factor_[target >= 0 ? target : -1 - target];
		if (target >= 0)
			m = offDiagonal[l].transpose();
		else
			m = offDiagonal[l];
	}
	// A rigid block's strain rows and columns carry no coupling.
	for (int j = 0; j < blocks; ++j) {
		for (int p = columnStart_[j]; p < columnStart_[j + 1]; ++p) {
			if (sizes_[rows_[p]] != kBlockDofs) factor_[p].bottomRows<6>().setZero();
			if (sizes_[j] != kBlockDofs) factor_[p].rightCols<6>().setZero();
		}
	}
	// The updates in the order their targets were listed. (Sharing a column's
	// rows among threads, each block written by one, gives the same bits, and
	// took 9.4 -> 6.2 ms for a dense 66-block factorisation on 2 threads; but
	// on the sparser factors of piles a region per long column cost more than
	// it saved, 2.9 -> 3.3 ms for 49 blocks at 30 %, and the 70-block drop ran
	// slower on 2 threads than on one: a worker that falls asleep between
	// regions is woken for each. So the factorisation is sequential;
	// components run in parallel when there are many.)
	const int* target = updateTarget_.data();
	for (int j = 0; j < blocks; ++j) {
		pivots_[j].compute(diagonal_[j]);
		if (pivots_[j].info() != Eigen::Success) return false;
		const int first = columnStart_[j], last = columnStart_[j + 1];
		const Matrix12& ljj = pivots_[j].matrixLLT();
		for (int p = first; p < last; ++p) solveTransposedLowerOnTheRight(factor_[p], ljj);
		for (int p = first; p < last; ++p) {
			const Matrix12& lij = factor_[p];
			subtractProductTransposed(diagonal_[rows_[p]], lij, lij);
			for (int q = first; q < p; ++q) subtractProductTransposed(factor_[*target++], lij, factor_[q]);
		}
	}
	return true;
}

void BlockCholesky::solve(Vector12* x) const {
	const int blocks = this->blocks();
	std::vector<Vector12> y(blocks);
	for (int k = 0; k < blocks; ++k) {
		const int j = inverse_[k];
		y[j] = x[k];
		if (sizes_[j] != kBlockDofs) y[j].tail<6>().setZero();
	}
	for (int j = 0; j < blocks; ++j) {
		pivots_[j].matrixL().solveInPlace(y[j]);
		for (int p = columnStart_[j]; p < columnStart_[j + 1]; ++p) subtractProduct(y[rows_[p]], factor_[p], y[j]);
	}
	for (int j = blocks - 1; j >= 0; --j) {
		for (int p = columnStart_[j]; p < columnStart_[j + 1]; ++p)
			subtractTransposedProduct(y[j], factor_[p], y[rows_[p]]);
		pivots_[j].matrixU().solveInPlace(y[j]);
	}
	for (int k = 0; k < blocks; ++k) x[k] = y[inverse_[k]];
}

std::size_t BlockCholesky::memoryBytes() const {
	return capacityBytes(inverse_) + capacityBytes(columnStart_) + capacityBytes(rows_) +
	       capacityBytes(linkTarget_) + capacityBytes(updateTarget_) + capacityBytes(sizes_) + capacityBytes(factor_) +
	       capacityBytes(diagonal_) + capacityBytes(pivots_);
}

}  // namespace dda
