#pragma once
// Range checks for numeric flags with a message a person reads in one go: CLI11's own
// NonNegativeNumber and PositiveNumber print the largest double (309 digits) as the upper end.
#include <CLI/CLI.hpp>

#include <string>

namespace bouncefit {

// Accepts a number >= 0 ("must be >= 0, not -1").
CLI::Validator NonNegative();
// Accepts a number > 0 ("must be > 0, not 0").
CLI::Validator Positive();

}  // namespace bouncefit
