#pragma once

// What the translation units of the Python module dynid._core share: the array types, the
// argument checks and the keyword parsing (python/dynid_module.cpp defines most of them,
// python/bind_*.cpp one binding area each).

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dynid/identification/identify.hpp"
#include "dynid/model/model.hpp"
#include "dynid/report/identification_report.hpp"

namespace dynid::binding {

namespace py = pybind11;

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Samples = Eigen::Ref<const RowMatrix>;

/// A JSON value as the Python object json.loads makes of it.
py::object to_python(const nlohmann::json& j);

/// The per-joint columns of the regressor from the boolean keywords.
ParameterLayout layout_of(bool armature, bool viscous, bool coulomb, bool offset, bool asymmetric);

/// `x` is rows × dof of `model` and finite, else a dynid::Error naming it.
void check_samples(const Model& model, const char* name, RowMatrix::Index rows, const Samples& x);

/// A run from its arrays, checked (check_samples).
JointRecord record_of(const Model& model, const Eigen::VectorXd& t, const Samples& q,
                      const Samples& tau, const std::optional<RowMatrix>& dq,
                      const std::optional<RowMatrix>& ddq);

/// The `estimator` keyword ('ols', 'wls' or 'rls') as identify's or payload's enum.
template <class Estimator>
Estimator estimator_of(const std::string& name, Estimator ols, Estimator wls, Estimator rls) {
  if (name == "ols") return ols;
  if (name == "wls") return wls;
  if (name == "rls") return rls;
  throw py::value_error("estimator must be 'ols', 'wls' or 'rls', not '" + name + "'");
}

/// The `confidence` keyword, checked.
double confidence_of(double level);

/// Every keyword is one of `keys`, else a TypeError naming it and the valid ones.
template <size_t N>
void check_keywords(const py::kwargs& kw, const char* const (&keys)[N]) {
  std::string valid;
  for (const char* k : keys) valid += (valid.empty() ? "" : ", ") + std::string(k);
  for (const auto& item : kw) {
    const std::string key = py::str(item.first);
    if (std::find_if(std::begin(keys), std::end(keys), [&](const char* k) { return key == k; }) ==
        std::end(keys)) {
      throw py::type_error("unknown option '" + key + "'; valid options are " + valid);
    }
  }
}

/// A keyword's value or `fallback` (of the keyword's type).
inline auto keyword_getter(const py::kwargs& kw) {
  return [&kw](const char* key, auto fallback) {
    using T = decltype(fallback);
    return kw.contains(key) ? kw[key].cast<T>() : fallback;
  };
}

/// The keywords only identify() takes (its model, runs and estimator stages).
struct IdentifyKeywords {
  std::string equations = "differential";  ///< --model
  int joint = 0;                           ///< --joint (experiments), 1-based; 0 = not given
  std::string repeat;                      ///< --repeat
  bool physical = false;                   ///< --physical
  std::string noise_std;                   ///< --noise-std q=S,tau=S (estimator 'ml')
};

/// IdentifyOptions from keyword arguments, their values echoed into `used` (the result's
/// `options`); an unknown key is a TypeError naming the valid ones. `identify`: where identify()'s
/// own keywords go; null for validate(), which then refuses them by name.
IdentifyOptions identify_options(const py::kwargs& kw, nlohmann::json& used,
                                 IdentifyKeywords* identify = nullptr);

/// An identify result dict (dynid.identify's, or a result.json loaded with json.load) read with
/// the checks of read_identification_result; a result of another robot is an error, as on the
/// command line. `what` names it in messages.
IdentifiedResultFile identified_result(const Model& model, const py::dict& result,
                                       const std::string& what);

/// Every warning of the library as a Python UserWarning (the command line prints them).
void warn_all(const std::vector<std::string>& warnings);

/// A dynid::UsageError of the library re-raised as a ValueError whose flags (--cutoff) read as
/// the keywords (cutoff_hz) of `keywords` {flag, keyword}.
[[noreturn]] void raise_with_keywords(
    const std::exception& e, std::initializer_list<std::pair<const char*, const char*>> keywords);

/// identify(), identify_runs(): the identification functions (python/bind_identification.cpp).
void bind_identification(py::module_& m);

/// excite(), simulate(), average(): the experiment functions (python/bind_experiments.cpp).
void bind_experiments(py::module_& m);

}  // namespace dynid::binding
