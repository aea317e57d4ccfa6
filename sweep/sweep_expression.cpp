#include "sweep/sweep_expression.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>

#include "common/input_error.hpp"

namespace lidarloop {
namespace {

// Recursive descent over the grammar
//   sum     = product { ('+' | '-') product }
//   product = unary { ('*' | '/') unary }
//   unary   = '-' unary | atom
//   atom    = number | name | '(' sum ')'
class Parser {
 public:
  Parser(const std::string& text, const std::map<std::string, double>& names) : text_(text), names_(names) {}

  double parse() {
    const double value = sum();
    skip_space();
    if (at_ < text_.size()) fail("unexpected '" + std::string(1, text_[at_]) + "'");
    return value;
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError("expression '" + text_ + "': " + why + " at character " + std::to_string(at_ + 1));
  }
  void skip_space() {
    while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
  }
  bool take(char c) {
    skip_space();
    if (at_ < text_.size() && text_[at_] == c) return ++at_, true;
    return false;
  }
  double sum() {
    double value = product();
    for (;;) {
      if (take('+'))
        value += product();
      else if (take('-'))
        value -= product();
      else
        return value;
    }
  }
  double product() {
    double value = unary();
    for (;;) {
      if (take('*'))
        value *= unary();
      else if (take('/'))
        value /= unary();
      else
        return value;
    }
  }
  double unary() { return take('-') ? -unary() : atom(); }
  double atom() {
    skip_space();
    if (take('(')) {
      const double value = sum();
      if (!take(')')) fail("missing ')'");
      return value;
    }
    if (at_ >= text_.size()) fail("a number or a name is missing");
    const char c = text_[at_];
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
      char* end = nullptr;
      const double value = std::strtod(text_.c_str() + at_, &end);
      if (end == text_.c_str() + at_) fail("a malformed number");
      at_ = size_t(end - text_.c_str());
      return value;
    }
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      const size_t start = at_;
      while (at_ < text_.size() && (std::isalnum(static_cast<unsigned char>(text_[at_])) || text_[at_] == '_')) ++at_;
      const std::string name = text_.substr(start, at_ - start);
      const auto it = names_.find(name);
      if (it == names_.end()) {
        at_ = start;
        fail("'" + name + "' is not a parameter of the sweep");
      }
      return it->second;
    }
    fail("unexpected '" + std::string(1, c) + "'");
  }

  const std::string& text_;
  const std::map<std::string, double>& names_;
  size_t at_ = 0;
};

}  // namespace

double evaluate_expression(const std::string& expression, const std::map<std::string, double>& names) {
  const double value = Parser(expression, names).parse();
  if (!std::isfinite(value)) throw InputError("expression '" + expression + "' is not a finite number");
  return value;
}

}  // namespace lidarloop
