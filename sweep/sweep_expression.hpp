#pragma once
// The arithmetic of a sweep's `set` entries: a scenario value derived from the varied parameters, as
// in `ego.route.offset: side * (4.5 - gap_m - 1.25)`. Numbers, parameter names, + - * /, unary minus
// and parentheses; nothing else, so a sweep file stays data.
#include <map>
#include <string>

namespace lidarloop {

// The value of `expression` with each name replaced by its value in `names`. InputError naming the
// expression for a syntax error, an unknown name or a non-finite result (a division by zero).
double evaluate_expression(const std::string& expression, const std::map<std::string, double>& names);

}  // namespace lidarloop
