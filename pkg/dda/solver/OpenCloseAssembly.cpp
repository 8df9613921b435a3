// The linear system of each solve of the open-close iteration (OpenClose.hpp):
// its structure from the contacts that carry terms, the blocks' own systems
// (kept within an attempt), the blocks that no contact couples (solved
// alone), and the contacts' terms (kept while their state stays).
#include "OpenClose.hpp"

#include "BlockKernels.hpp"
#include "StepClock.hpp"

#include <algorithm>

namespace dda {

namespace {
// Heap for the contact terms kept within an attempt
// (OpenCloseIteration::keptTerms_): about 20,000 contacts; the others' terms
// are made at every solve.
constexpr std::size_t kKeptTermsBytes = std::size_t(16) << 20;
}  // namespace

void OpenCloseIteration::buildSystemStructure(const Attempt& attempt) {
	const int movingBlocks = static_cast<int>(moving_.size());
	StepStatistics& stats = attempt.stats;
	links_.clear();
	hasSprings_.assign(movingBlocks, 0);
	for (int k = 0; k < movingBlocks; ++k) hasSprings_[k] = !attempt.blocks[moving_[k]].fixedPoints.empty();
	for (const Contact& contact : attempt.contacts) {
		// No terms (open, and no tangential spring): couples nothing.
		if (!hasNormalTerms(contact) && tangentialTerm(contact) == TangentialTerm::None) continue;
		const int mi = movingIndex_[contact.bodyI], mj = movingIndex_[contact.bodyJ];
		if (mi >= 0) hasSprings_[mi] = 1;
		if (mj >= 0) hasSprings_[mj] = 1;
		if (mi >= 0 && mj >= 0) links_.emplace_back(mi, mj);
	}
	coupled_.build(movingBlocks, links_, hasSprings_, blockUnknowns_);
	aloneUnknowns_ = 0;
	for (int k = 0; k < movingBlocks; ++k)
		if (!hasSprings_[k]) aloneUnknowns_ += blockUnknowns_[k];
	++stats.systemStructures;
	// A block left alone is a component of its own.
	const int alone = movingBlocks - coupled_.blocks();
	stats.components = coupled_.components() + alone;
	stats.largestComponent = std::max(coupled_.largestComponent(), alone > 0 ? 1 : 0);
}

void OpenCloseIteration::assembleOwnSystems(const Attempt& attempt) {
	const int n = static_cast<int>(moving_.size());
	const int kept = static_cast<int>(ownSystems_.size());
	int count = kept;
	for (int k = 0; k < n; ++k)
		if (coupled_.coupled(k) && ownSystemOf_[k] < 0) ownSystemOf_[k] = count++;
	ownSystems_.resize(count);
#pragma omp parallel for schedule(static) if (count - kept >= kMinBlocksForThreads)
	for (int k = 0; k < n; ++k)
		if (ownSystemOf_[k] >= kept)
			assembleBlock(attempt.blocks[moving_[k]], attempt.settings, attempt.dt, startAccelerationOf(k),
			              ownSystems_[ownSystemOf_[k]]);
}

void OpenCloseIteration::solveAloneBlocks(const Attempt& attempt) {
	const int n = static_cast<int>(moving_.size());
	int unsolved = 0;
	for (int k = 0; k < n; ++k) {
		if (coupled_.coupled(k))
			solvedAlone_[k] = 0;  // coupled_.solve writes its solution
		else
			unsolved += !solvedAlone_[k];
	}
	// Threads only for work: each parallel region can wait a scheduler slice
	// on a loaded machine (kMinBlocksForThreads).
#pragma omp parallel for schedule(static) if (unsolved >= kMinBlocksForThreads)
	for (int k = 0; k < n; ++k) {
		if (coupled_.coupled(k) || solvedAlone_[k]) continue;
		const Block& block = attempt.blocks[moving_[k]];
		BlockSystem system;
		assembleBlock(block, attempt.settings, attempt.dt, startAccelerationOf(k), system);
		solutions_[k] = solveBlock(block, system);
		solvedAlone_[k] = 1;
	}
}

void OpenCloseIteration::assembleContacts(const Attempt& attempt) {
	StepStatistics& stats = attempt.stats;
	ContactTerms work;
	const std::vector<Contact>& contacts = attempt.contacts;
	keptTermsOf_.resize(contacts.size(), -1);
	keptTermsKey_.resize(contacts.size(), 0);
	for (std::size_t c = 0; c < contacts.size(); ++c) {
		const Contact& contact = contacts[c];
		const int bi = contact.bodyI, bj = contact.bodyJ;
		const bool normalTerms = hasNormalTerms(contact);
		const TangentialTerm tangential = tangentialTerm(contact);
		// No terms (what contactTerms returns false for).
		if (!normalTerms && tangential == TangentialTerm::None) continue;
		// Kept terms while the state is the one they were made for (see
		// keptTerms_ in OpenClose.hpp): not a slipping contact's, which
		// depend on its stretch, nor a secant's (gamma < 1), which depend on
		// its trial gap; both are made anew at every solve.
		const bool keepable =
		    tangential != TangentialTerm::FrictionLoad && !(normalTerms && contact.secantWeight > 0);
		const unsigned char key = static_cast<unsigned char>(1 + normalTerms + 2 * static_cast<int>(tangential));
		const ContactTerms* termsOf = &work;
		const int kept = keptTermsOf_[c];
		if (keepable && kept >= 0 && keptTermsKey_[c] == key) {
			termsOf = &keptTerms_[kept];
		} else {
			contactTerms(contact, attempt.blocks[bi], attempt.blocks[bj], work);
			if (keepTerms_ && keepable &&
			    (kept >= 0 || (keptTerms_.size() + 1) * sizeof(ContactTerms) <= kKeptTermsBytes)) {
				if (kept < 0) {
					// Grown by hand so that its capacity stays within the budget.
					if (keptTerms_.size() == keptTerms_.capacity())
						keptTerms_.reserve(std::min(std::max<std::size_t>(64, 2 * keptTerms_.capacity()),
						                            kKeptTermsBytes / sizeof(ContactTerms)));
					keptTermsOf_[c] = static_cast<int>(keptTerms_.size());
					keptTerms_.emplace_back();
				}
				keptTerms_[keptTermsOf_[c]] = work;
				keptTermsKey_[c] = key;
			}
		}
		const ContactTerms& terms = *termsOf;
		// An open contact may carry its tangential spring alone (its limit is
		// held for the pass): only closed ones have a normal spring.
		stats.normalTerms += normalTerms;
		stats.frictionTerms += tangential != TangentialTerm::None;
		const int mi = movingIndex_[bi], mj = movingIndex_[bj];
		Matrix12* diagonalI = mi >= 0 ? &coupled_.diagonal(mi) : nullptr;
		Matrix12* diagonalJ = mj >= 0 ? &coupled_.diagonal(mj) : nullptr;
		bool transposed = false;
		Matrix12* offDiagonal = mi >= 0 && mj >= 0 ? &coupled_.offDiagonal(mi, mj, transposed) : nullptr;
		// Each rank-one term w v v^T by its 12x12 blocks: (i, i), (j, j) and
		// the stored off-diagonal one, (i, j), or (j, i) when transposed.
		for (int r = 0; r < terms.rank; ++r) {
			const Vector24 scaled = terms.weight[r] * terms.vector[r];
			const double* vi = terms.vector[r].data();
			const double* vj = vi + 12;
			const double* si = scaled.data();
			const double* sj = si + 12;
			if (diagonalI) addOuterProduct(*diagonalI, si, vi);
			if (diagonalJ) addOuterProduct(*diagonalJ, sj, vj);
			if (offDiagonal) {
				if (transposed)
					addOuterProduct(*offDiagonal, sj, vi);
				else
					addOuterProduct(*offDiagonal, si, vj);
			}
		}
		if (diagonalI) coupled_.force(mi) += terms.force.head<12>();
		if (diagonalJ) coupled_.force(mj) += terms.force.tail<12>();
		if (prescribed_ && (mi < 0 || mj < 0)) addKnownDisplacement(terms, mi, mj, bi, bj);
	}
}

void OpenCloseIteration::addKnownDisplacement(const ContactTerms& terms, int mi, int mj, int bi, int bj) {
	// The moving side (offset 0 for i, 12 for j) and the known side's D.
	const bool iMoves = mi >= 0;
	if (iMoves == (mj >= 0)) return;
	const Vector12& known = (*prescribed_)[iMoves ? bj : bi];
	if (known.isZero()) return;
	const int own = iMoves ? 0 : 12, other = iMoves ? 12 : 0;
	Vector12& force = coupled_.force(iMoves ? mi : mj);
	for (int r = 0; r < terms.rank; ++r)
		force -= (terms.weight[r] * terms.vector[r].segment<12>(other).dot(known)) * terms.vector[r].segment<12>(own);
}

}  // namespace dda
