#pragma once
// The cloth's force terms, in the order each particle's row sums them (cloth_term.h says what a term is).
// A new force is one header (or header and source) and one entry here; the spring terms stay together.
#include <tuple>

#include "sim/cloth/air_drag_term.h"
#include "sim/cloth/contact_term.h"
#include "sim/cloth/friction_term.h"
#include "sim/cloth/gravity_term.h"
#include "sim/cloth/spring_damping_term.h"
#include "sim/cloth/spring_term.h"

namespace kf {

using ClothTerms = std::tuple<GravityTerm, AirDragTerm, SpringTerm, SpringDampingTerm, ContactTerm, FrictionTerm>;

}  // namespace kf
