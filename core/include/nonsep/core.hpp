#pragma once
// Everything of nonsep::core in one include.
#include "nonsep/core/chin_basic_step.hpp"
#include "nonsep/core/energy.hpp"
#include "nonsep/core/error.hpp"
#include "nonsep/core/fraction.hpp"
#include "nonsep/core/integrator.hpp"
#include "nonsep/core/integrator_description.hpp"
#include "nonsep/core/model.hpp"
#include "nonsep/core/multi_product_expansion.hpp"
#include "nonsep/core/phase_space_batch.hpp"
#include "nonsep/core/triplet_composition.hpp"
