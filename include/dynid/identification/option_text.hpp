#pragma once

// identify's options in the text form the command line takes and a result JSON stores them
// (options.friction, options.filter), read once for the CLI, stored results and the Python module.

#include <string>

#include "dynid/closed_loop/closed_loop_options.hpp"
#include "dynid/identification/record.hpp"
#include "dynid/regressor/parameter_layout.hpp"

namespace dynid {

/// identify's friction set from its text form, as `--friction` takes it and a result stores it in
/// options.friction: "none" or a comma list of viscous, coulomb, offset, asymmetric (asymmetric
/// implies viscous and Coulomb, seed 2 eq. 2); `armature` adds the Ia columns. Throws
/// dynid::UsageError naming the unknown term.
ParameterLayout friction_layout(const std::string& text, bool armature);

/// The low-pass of `--filter` (and options.filter of a result) read into `signal`: "auto" leaves it
/// unchanged, "none" turns filtering off, "butterworth[:ORDER]" and
/// "chebyshev[:ORDER[:RIPPLE_DB]]" set family, order (Chebyshev default 8, seed 2 §3.4) and
/// ripple [dB]. Throws dynid::UsageError naming the forms.
void apply_filter_text(const std::string& text, SignalOptions& signal);

/// The projection's FIR orders from `--fir M1,M2` (seed 2 eqs. 10–11: M1 future and M2 past
/// reference lags, integers ≥ 0) into projection.m1, m2. Throws dynid::UsageError naming the form.
void apply_fir_text(const std::string& text, ProjectionOptions& projection);

}  // namespace dynid
