#include "AffineCoarseSpace.hpp"

#include "dda/core/CapacityBytes.hpp"

#include <algorithm>

namespace dda {

namespace {

// Coarse systems larger than this are grouped again: the coarse Cholesky's
// cost grows faster than its blocks (a jointed mass's graph is three
// dimensional), so its size is bounded.
constexpr int kMaxAggregates = 400;

using Matrix3x9 = Eigen::Matrix<double, 3, 9>;

// One greedy grouping of a graph (rows/neighbours, ascending): per node its
// group; returns the number of groups.
int groupGraph(int nodes, const std::vector<int>& rows, const std::vector<int>& neighbours, std::vector<int>& group) {
	group.assign(nodes, -1);
	int count = 0;
	for (int k = 0; k < nodes; ++k) {
		if (group[k] >= 0) continue;
		bool free = true;
		for (int e = rows[k]; e < rows[k + 1] && free; ++e) free = group[neighbours[e]] < 0;
		if (!free) continue;
		group[k] = count;
		for (int e = rows[k]; e < rows[k + 1]; ++e) group[neighbours[e]] = count;
		++count;
	}
	for (int k = 0; k < nodes; ++k) {
		if (group[k] >= 0) continue;
		for (int e = rows[k]; e < rows[k + 1] && group[k] < 0; ++e) group[k] = group[neighbours[e]];
		if (group[k] < 0) group[k] = count++;
	}
	return count;
}

// The graph of the groups: group a's neighbouring groups, ascending.
void groupAdjacency(int nodes, const std::vector<int>& rows, const std::vector<int>& neighbours,
                    const std::vector<int>& group, int groups, std::vector<int>& groupRows,
                    std::vector<int>& groupNeighbours) {
	std::vector<std::vector<int>> adjacent(groups);
	for (int k = 0; k < nodes; ++k)
		for (int e = rows[k]; e < rows[k + 1]; ++e)
			if (group[neighbours[e]] != group[k]) adjacent[group[k]].push_back(group[neighbours[e]]);
	groupRows.assign(groups + 1, 0);
	groupNeighbours.clear();
	for (int a = 0; a < groups; ++a) {
		std::sort(adjacent[a].begin(), adjacent[a].end());
		adjacent[a].erase(std::unique(adjacent[a].begin(), adjacent[a].end()), adjacent[a].end());
		groupNeighbours.insert(groupNeighbours.end(), adjacent[a].begin(), adjacent[a].end());
		groupRows[a + 1] = static_cast<int>(groupNeighbours.size());
	}
}

// Y = K R_j: R_j = [[I, B_j], [0, I]] with the strain block scaled by 0
// for a rigid block (its strain columns then come from B_j alone).
Matrix12 timesMap(const Matrix12& k, const Matrix3x9& b, bool rigid) {
	Matrix12 y;
	y.leftCols<3>() = k.leftCols<3>();
	y.rightCols<9>().noalias() = k.leftCols<3>() * b;
	y.middleCols<3>(3) += k.middleCols<3>(3);
	if (!rigid) y.rightCols<6>() += k.rightCols<6>();
	return y;
}

// R_i^T Y.
Matrix12 mapTransposeTimes(const Matrix3x9& b, bool rigid, const Matrix12& y) {
	Matrix12 z;
	z.topRows<3>() = y.topRows<3>();
	z.bottomRows<9>().noalias() = b.transpose() * y.topRows<3>();
	z.middleRows<3>(3) += y.middleRows<3>(3);
	if (!rigid) z.bottomRows<6>() += y.bottomRows<6>();
	return z;
}

}  // namespace

void AffineCoarseSpace::aggregate(const Fine& fine) {
	const int n = fine.matrix.blocks;
	std::vector<int> rows(fine.rows, fine.rows + n + 1), neighbours(fine.neighbours, fine.neighbours + fine.rows[n]);
	int count = groupGraph(n, rows, neighbours, aggregateOf_);
	std::vector<int> group, groupRows, groupNeighbours;
	while (count > kMaxAggregates) {
		groupAdjacency(n, rows, neighbours, aggregateOf_, count, groupRows, groupNeighbours);
		const int regrouped = groupGraph(count, groupRows, groupNeighbours, group);
		if (regrouped >= count) break;
		for (int& a : aggregateOf_) a = group[a];
		count = regrouped;
	}
	aggregateStart_.assign(count + 1, 0);
	for (int k = 0; k < n; ++k) ++aggregateStart_[aggregateOf_[k] + 1];
	for (int a = 0; a < count; ++a) aggregateStart_[a + 1] += aggregateStart_[a];
	members_.resize(n);
	std::vector<int> next(aggregateStart_.begin(), aggregateStart_.end() - 1);
	for (int k = 0; k < n; ++k) members_[next[aggregateOf_[k]]++] = k;
	reference_.assign(count, Vector3::Zero());
	coarseSizes_.assign(count, kRigidBlockDofs);
	for (int a = 0; a < count; ++a) {
		for (int m = aggregateStart_[a]; m < aggregateStart_[a + 1]; ++m) {
			reference_[a] += fine.matrix.centroids[members_[m]];
			if (fine.matrix.sizes[members_[m]] == kBlockDofs) coarseSizes_[a] = kBlockDofs;
		}
		reference_[a] /= aggregateStart_[a + 1] - aggregateStart_[a];
	}
}

void AffineCoarseSpace::formMaps(const Fine& fine) {
	const int n = fine.matrix.blocks;
	maps_.resize(n);
	rigid_.resize(n);
	for (int k = 0; k < n; ++k) {
		maps_[k] = displacementMatrix(fine.matrix.centroids[k] - reference_[aggregateOf_[k]]).rightCols<9>();
		rigid_[k] = fine.matrix.sizes[k] != kBlockDofs;
	}
}

void AffineCoarseSpace::formCoarseMatrix(const Fine& fine) {
	const int n = fine.matrix.blocks, count = aggregates();
	coarseLinks_.clear();
	for (int l = 0; l < fine.matrix.linkCount; ++l) {
		const int a = aggregateOf_[fine.matrix.links[l].first], b = aggregateOf_[fine.matrix.links[l].second];
		if (a != b) coarseLinks_.emplace_back(std::min(a, b), std::max(a, b));
	}
	std::sort(coarseLinks_.begin(), coarseLinks_.end());
	coarseLinks_.erase(std::unique(coarseLinks_.begin(), coarseLinks_.end()), coarseLinks_.end());
	coarseDiagonal_.assign(count, Matrix12::Zero());
	coarseOffDiagonal_.assign(coarseLinks_.size(), Matrix12::Zero());
	for (int k = 0; k < n; ++k) {
		const Matrix12 d = fine.matrix.diagonal[k].selfadjointView<Eigen::Lower>();
		coarseDiagonal_[aggregateOf_[k]] += mapTransposeTimes(maps_[k], rigid_[k], timesMap(d, maps_[k], rigid_[k]));
	}
	for (int l = 0; l < fine.matrix.linkCount; ++l) {
		const auto [lo, hi] = fine.matrix.links[l];
		const Matrix12 g =
		    mapTransposeTimes(maps_[lo], rigid_[lo], timesMap(fine.matrix.offDiagonal[l], maps_[hi], rigid_[hi]));
		const int a = aggregateOf_[lo], b = aggregateOf_[hi];
		if (a == b) {
			coarseDiagonal_[a] += g;
			coarseDiagonal_[a] += g.transpose();
			continue;
		}
		const auto link = std::lower_bound(coarseLinks_.begin(), coarseLinks_.end(),
		                                   std::make_pair(std::min(a, b), std::max(a, b)));
		Matrix12& m = coarseOffDiagonal_[link - coarseLinks_.begin()];
		if (a < b)
			m += g;
		else
			m += g.transpose();
	}
}

bool AffineCoarseSpace::prepare(const Fine& fine) {
	ready_ = false;
	aggregate(fine);
	formMaps(fine);
	formCoarseMatrix(fine);
	cholesky_.analyse(aggregates(), coarseLinks_);
	ready_ = cholesky_.factorize(coarseDiagonal_.data(), coarseOffDiagonal_.data(), coarseSizes_.data());
	coarse_.resize(aggregates());
	return ready_;
}

void AffineCoarseSpace::addCorrection(const std::vector<Vector12>& r, std::vector<Vector12>& z, bool threaded) const {
	if (!ready_) return;
	const int count = aggregates(), n = static_cast<int>(aggregateOf_.size());
	// Restriction P^T r, an aggregate's blocks in ascending order.
#pragma omp parallel for schedule(static) if (threaded)
	for (int a = 0; a < count; ++a) {
		Vector12 sum = Vector12::Zero();
		for (int m = aggregateStart_[a]; m < aggregateStart_[a + 1]; ++m) {
			const int k = members_[m];
			sum.head<3>() += r[k].head<3>();
			sum.tail<9>().noalias() += maps_[k].transpose() * r[k].head<3>();
			sum.segment<3>(3) += r[k].segment<3>(3);
			if (!rigid_[k]) sum.tail<6>() += r[k].tail<6>();
		}
		coarse_[a] = sum;
	}
	cholesky_.solve(coarse_.data());
	// Prolongation: z_k += R_k y_a.
#pragma omp parallel for schedule(static) if (threaded)
	for (int k = 0; k < n; ++k) {
		const Vector12& y = coarse_[aggregateOf_[k]];
		Vector12& out = z[k];
		out.head<3>() += y.head<3>();
		out.head<3>().noalias() += maps_[k] * y.tail<9>();
		out.segment<3>(3) += y.segment<3>(3);
		if (!rigid_[k]) out.tail<6>() += y.tail<6>();
	}
}

std::size_t AffineCoarseSpace::memoryBytes() const {
	return capacityBytes(aggregateOf_) + capacityBytes(aggregateStart_) + capacityBytes(members_) +
	       capacityBytes(reference_) + capacityBytes(coarseSizes_) + capacityBytes(maps_) + capacityBytes(rigid_) +
	       capacityBytes(coarseDiagonal_) + capacityBytes(coarseOffDiagonal_) + capacityBytes(coarseLinks_) +
	       cholesky_.memoryBytes() + capacityBytes(coarse_);
}

}  // namespace dda
