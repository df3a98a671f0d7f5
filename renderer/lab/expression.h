#pragma once
// f(x) typed as an expression for the 1D lab, e.g. "sin(pi*x)^2" or
// "exp(-x)*x^3": muParser's syntax (+ - * / ^, sin cos tan asin acos atan
// sinh cosh tanh exp ln log log2 log10 sqrt sign rint abs min max sum avg,
// the constants _pi and _e, and pi, e here), with the variable x.
#include <functional>
#include <memory>
#include <string>

namespace pdflab::lab {

class Expression {
 public:
  // Throws InputError naming the problem ("f(x) = 'sin(x': unexpected end of
  // the expression at position 6") for text that does not parse, uses another
  // variable, or has no finite value anywhere on [kLow, kHigh].
  static Expression parse(const std::string& text);
  double operator()(double x) const;
  const std::string& text() const { return text_; }
  // A callable copy (each evaluates on its own parser: not shared across threads).
  std::function<double(double)> function() const;

  struct Impl;  // a muParser parser and its variable

 private:
  std::shared_ptr<Impl> impl_;
  std::string text_;
};

// The integral of f over [a, b] by adaptive Simpson quadrature (Lyness's
// criterion per interval, with Richardson's correction), to about `tolerance`
// in absolute terms; intervals stop splitting at depth 40 or after 400,000
// evaluations in all. A non-finite value
// of f anywhere sampled makes the result NaN: the caller says "not finite".
double integrate(const std::function<double(double)>& f, double a, double b, double tolerance = 1e-10);

}  // namespace pdflab::lab
