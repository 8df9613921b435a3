#include "Block.hpp"

#include <cmath>
#include <sstream>

namespace dda {

void validateMaterial(const Material& material) {
	std::ostringstream message;
	if (!(std::isfinite(material.density) && material.density > 0))
		message << "density must be positive and finite, got " << material.density << " kg/m^3";
	else if (!(std::isfinite(material.young) && material.young > 0))
		message << "Young's modulus must be positive and finite, got " << material.young << " Pa";
	else if (!(std::isfinite(material.poisson) && material.poisson > -1 && material.poisson < 0.5))
		message << "Poisson's ratio must lie in (-1, 0.5), got " << material.poisson;
	else if (!(std::isfinite(material.frictionAngle) && material.frictionAngle >= 0 && material.frictionAngle < M_PI / 2))
		message << "friction angle must lie in [0, pi/2) rad, got " << material.frictionAngle << " rad";
	else if (!(std::isfinite(material.cohesion) && material.cohesion >= 0))
		message << "cohesion must be >= 0 and finite, got " << material.cohesion << " Pa";
	else if (!(std::isfinite(material.tensileStrength) && material.tensileStrength >= 0))
		message << "tensile strength must be >= 0 and finite, got " << material.tensileStrength << " Pa";
	else
		return;
	throw InputError(message.str());
}

int bodyIndex(const std::vector<Block>& blocks, int index) {
	const int body = blocks[index].body;
	return body < 0 ? index : body;
}

Vector3 interiorPoint(const Block& block) {
	if (!block.isPart()) return block.centroid;
	Vector3 sum = Vector3::Zero();
	for (const Vector3& x : block.vertices) sum += x;
	return sum / static_cast<double>(block.vertices.size());
}

}  // namespace dda
