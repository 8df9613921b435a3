#include "Collider.hpp"

#include "dda/core/Errors.hpp"

namespace dda {

void Collider::setCover(double /*criticalLength*/, int /*segments*/) {
	throw InputError("the scene's collider is not MSC");
}

}  // namespace dda
