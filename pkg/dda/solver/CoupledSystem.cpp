#include "CoupledSystem.hpp"

#include <Eigen/Cholesky>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace dda {

namespace {

std::uint64_t linkKey(int a, int b) {
	return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

int findRoot(std::vector<int>& parent, int k) {
	while (parent[k] != k) {
		parent[k] = parent[parent[k]];
		k = parent[k];
	}
	return k;
}

}  // namespace

void CoupledSystem::build(int movingBlocks, const std::vector<std::pair<int, int>>& links,
                          const std::vector<char>& hasSprings, const std::vector<int>& unknowns) {
	hasSprings_ = hasSprings;
	unknowns_ = unknowns;
	std::vector<int> parent(movingBlocks);
	std::iota(parent.begin(), parent.end(), 0);
	offDiagonalIndex_.clear();
	offDiagonalPairs_.clear();
	for (auto [a, b] : links) {
		if (a == b) continue;
		const int lo = std::min(a, b), hi = std::max(a, b);
		if (offDiagonalIndex_.emplace(linkKey(lo, hi), static_cast<int>(offDiagonalPairs_.size())).second)
			offDiagonalPairs_.emplace_back(lo, hi);
		const int ra = findRoot(parent, a), rb = findRoot(parent, b);
		if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
	}
	componentOf_.assign(movingBlocks, -1);
	localIndex_.assign(movingBlocks, -1);
	components_.clear();
	std::vector<int> componentOfRoot(movingBlocks, -1);
	for (int k = 0; k < movingBlocks; ++k) {
		const int root = findRoot(parent, k);
		if (componentOfRoot[root] < 0) {
			componentOfRoot[root] = static_cast<int>(components_.size());
			components_.emplace_back();
		}
		const int c = componentOfRoot[root];
		componentOf_[k] = c;
		localIndex_[k] = static_cast<int>(components_[c].size());
		components_[c].push_back(k);
	}
	componentLinks_.assign(components_.size(), {});
	for (int slot = 0; slot < static_cast<int>(offDiagonalPairs_.size()); ++slot)
		componentLinks_[componentOf_[offDiagonalPairs_[slot].first]].push_back(slot);
	offDiagonal_.resize(offDiagonalPairs_.size());
	componentUnknowns_.assign(components_.size(), 0);
	diagonal_.resize(movingBlocks);
	force_.resize(movingBlocks);
}

void CoupledSystem::reset(const std::vector<BlockSystem>& blockSystems) {
	for (std::size_t k = 0; k < diagonal_.size(); ++k) {
		diagonal_[k] = blockSystems[k].stiffness;
		force_[k] = blockSystems[k].force;
	}
	for (Matrix12& m : offDiagonal_) m.setZero();
}

Matrix12& CoupledSystem::offDiagonal(int a, int b, bool& transposed) {
	transposed = a > b;
	return offDiagonal_[offDiagonalIndex_.at(linkKey(std::min(a, b), std::max(a, b)))];
}

int CoupledSystem::largestComponent() const {
	std::size_t largest = 0;
	for (const auto& c : components_) largest = std::max(largest, c.size());
	return static_cast<int>(largest);
}

void CoupledSystem::solve(const std::vector<const Block*>& blocks, std::vector<Vector12>& solutions, int threadsFrom) {
	const int count = components();
	bool failed = false;
#pragma omp parallel for schedule(dynamic) if (count >= threadsFrom)
	for (int c = 0; c < count; ++c) {
		const std::vector<int>& members = components_[c];
		if (members.size() == 1) {
			const int k = members[0];
			componentUnknowns_[c] = unknowns_[k];
			if (!hasSprings_[k]) {
				solutions[k] = solveBlock(*blocks[k], BlockSystem{diagonal_[k], force_[k]});
			} else if (unknowns_[k] == kRigidBlockDofs) {
				Eigen::LLT<Matrix6> llt(diagonal_[k].topLeftCorner<kRigidBlockDofs, kRigidBlockDofs>());
				if (llt.info() != Eigen::Success) {
#pragma omp atomic write
					failed = true;
				}
				solutions[k].head<kRigidBlockDofs>() = llt.solve(force_[k].head<kRigidBlockDofs>());
				solutions[k].tail<kBlockDofs - kRigidBlockDofs>().setZero();
			} else {
				Eigen::LLT<Matrix12> llt(diagonal_[k]);
				if (llt.info() != Eigen::Success) {
#pragma omp atomic write
					failed = true;
				}
				solutions[k] = llt.solve(force_[k]);
			}
			continue;
		}
		// Variable block sizes: member l's unknowns start at offset[l] and
		// number unknowns_[k] (12, or 6 for a rigid block, whose strain rows
		// and columns of the stored 12x12 blocks are left out).
		std::vector<int> offset(members.size() + 1, 0);
		for (std::size_t l = 0; l < members.size(); ++l) offset[l + 1] = offset[l] + unknowns_[members[l]];
		const int n = offset.back();
		componentUnknowns_[c] = n;
		std::vector<Eigen::Triplet<double>> entries;
		entries.reserve(members.size() * 78 + componentLinks_[c].size() * 144);
		Eigen::VectorXd rhs(n);
		for (std::size_t l = 0; l < members.size(); ++l) {
			const int k = members[l];
			const int base = offset[l], size = unknowns_[k];
			for (int col = 0; col < size; ++col)
				for (int row = col; row < size; ++row) entries.emplace_back(base + row, base + col, diagonal_[k](row, col));
			rhs.segment(base, size) = force_[k].head(size);
		}
		for (int slot : componentLinks_[c]) {
			// Stored block is K[lo][hi]; the lower triangle holds K[hi][lo] = its transpose.
			const auto [lo, hi] = offDiagonalPairs_[slot];
			const int rowBase = offset[localIndex_[hi]], colBase = offset[localIndex_[lo]];
			const int rows = unknowns_[hi], cols = unknowns_[lo];
			const Matrix12& m = offDiagonal_[slot];
			for (int col = 0; col < cols; ++col)
				for (int row = 0; row < rows; ++row) entries.emplace_back(rowBase + row, colBase + col, m(col, row));
		}
		Eigen::SparseMatrix<double> K(n, n);
		K.setFromTriplets(entries.begin(), entries.end());
		Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> llt(K);
		if (llt.info() != Eigen::Success) {
#pragma omp atomic write
			failed = true;
			continue;
		}
		const Eigen::VectorXd x = llt.solve(rhs);
		for (std::size_t l = 0; l < members.size(); ++l) {
			const int k = members[l], size = unknowns_[k];
			solutions[k].setZero();
			solutions[k].head(size) = x.segment(offset[l], size);
		}
	}
	if (failed) throw std::runtime_error("the DDA system is not positive definite (Cholesky failed)");
	// Summed in component order after the loop, so the count does not depend
	// on the thread count.
	solvedUnknowns_ = 0;
	for (int c = 0; c < count; ++c) solvedUnknowns_ += componentUnknowns_[c];
}

}  // namespace dda
