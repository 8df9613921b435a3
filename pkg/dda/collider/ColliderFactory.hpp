// The broad phases by name: the one list of colliders. A collider's name is
// its name() (Collider.hpp, MSCCollider.hpp); Python reads the list as
// _core.colliderNames() and DDAIntegrator's collider parameter allows these.
#pragma once

#include "Collider.hpp"

#include <memory>
#include <string>
#include <vector>

namespace dda {

// DESS (the default), NBS, AllPairs, MSC, in that order.
const std::vector<std::string>& colliderNames();
// "DESS, NBS, AllPairs, MSC", for messages.
std::string colliderList();
// A new collider of that name, or nullptr when no collider has it.
std::unique_ptr<Collider> makeCollider(const std::string& name);

}  // namespace dda
