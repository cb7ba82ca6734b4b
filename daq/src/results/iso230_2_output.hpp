#pragma once
// Text and JSON presentation of ISO 230-2 evaluations, plans and uncertainty budgets.
#include <nlohmann/json.hpp>

#include "cal/analysis/iso230_2.hpp"
#include "cal/analysis/uncertainty.hpp"
#include "cal/storage/store.hpp"

namespace daq {

nlohmann::json to_json(const cal::iso230_2::Evaluation& e);  // schema caldaq.iso230-2.v1
nlohmann::json to_json(const cal::iso230_2::Plan& p);        // schema caldaq.plan.v1
nlohmann::json to_json(const cal::unc::Budget& b);
void print(const cal::iso230_2::Evaluation& e);
// "5 runs per direction", or where targets differ "4 to 5 runs per direction (4: 100.000 mm
// up, ...)": the evaluation's `runs` is the smallest, which alone would misstate the others.
std::string runs_text(const cal::iso230_2::Evaluation& e);
std::string runs_text(const nlohmann::json& evaluation);  // from a caldaq.iso230-2.v1 document
void print(const cal::unc::Budget& b, double length_m);
// The result of a test kind other than positioning (daq/src/runner/kinds): a profile
// (caldaq.profile.v1: straightness, angular, roll) or a rotary axis's ISO 230-2 evaluation
// (caldaq.rotary.v1, targets in deg and deviations in arcsec), as text.
void print_kind_result(const nlohmann::json& j, const std::string& component);
// The stored captured stops of a run as the deviations ISO 230-2 evaluates.
std::vector<cal::iso230_2::Measurement> measurements(
    const std::vector<cal::storage::CapturedTarget>& targets);

}  // namespace daq
