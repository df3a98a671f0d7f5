#include "renderer/lab/expression.h"

#include "renderer/error.h"
#include "renderer/lab/lab1d.h"

#include <muParser.h>

#include <cmath>
#include <numbers>

namespace pdflab::lab {

struct Expression::Impl {
  mu::Parser parser;
  double x = 0.0;
};

namespace {

std::shared_ptr<Expression::Impl> make_parser(const std::string& text) {
  auto impl = std::make_shared<Expression::Impl>();
  impl->parser.DefineVar("x", &impl->x);
  impl->parser.DefineConst("pi", std::numbers::pi);
  impl->parser.DefineConst("e", std::numbers::e);
  impl->parser.SetExpr(text);
  return impl;
}

}  // namespace

Expression Expression::parse(const std::string& text) {
  const std::string quoted = "f(x) = '" + text + "'";
  if (text.find_first_not_of(" \t") == std::string::npos) throw InputError(quoted + ": empty; type e.g. x^2 or sin(pi*x)");
  Expression e;
  e.text_ = text;
  try {
    e.impl_ = make_parser(text);
    // muParser reads the text at the first evaluation: errors show here.
    bool finite_somewhere = false;
    for (int i = 0; i <= 16; ++i) {
      e.impl_->x = kLow + (kHigh - kLow) * i / 16.0;
      finite_somewhere = finite_somewhere || std::isfinite(e.impl_->parser.Eval());
    }
    if (!finite_somewhere) throw InputError(quoted + ": has no finite value on [0, 2]");
  } catch (const mu::Parser::exception_type& err) {
    std::string message = err.GetMsg();
    if (!message.empty() && message.back() == '.') message.pop_back();
    throw InputError(quoted + ": " + message);
  }
  return e;
}

double Expression::operator()(double x) const {
  impl_->x = x;
  try {
    return impl_->parser.Eval();
  } catch (const mu::Parser::exception_type&) {
    return std::nan("");
  }
}

std::function<double(double)> Expression::function() const {
  // Its own parser: a copy evaluates without touching this one's variable.
  auto own = make_parser(text_);
  return [own](double x) {
    own->x = x;
    try {
      return own->parser.Eval();
    } catch (const mu::Parser::exception_type&) {
      return std::nan("");
    }
  };
}

namespace {

struct Simpson {
  const std::function<double(double)>& f;
  bool finite = true;
  long evaluations = 0;  // an oscillating f would split forever: the budget ends it
  static constexpr long kBudget = 400000;

  double at(double x) {
    ++evaluations;
    const double v = f(x);
    finite = finite && std::isfinite(v);
    return v;
  }
  double refine(double a, double b, double fa, double fm, double fb, double whole, double tolerance, int depth) {
    const double m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
    const double flm = at(lm), frm = at(rm);
    const double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
    const double right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    const double delta = left + right - whole;
    if (!finite || depth <= 0 || evaluations > kBudget || std::abs(delta) <= 15.0 * tolerance)
      return left + right + delta / 15.0;
    return refine(a, m, fa, flm, fm, left, tolerance * 0.5, depth - 1) +
           refine(m, b, fm, frm, fb, right, tolerance * 0.5, depth - 1);
  }
};

}  // namespace

double integrate(const std::function<double(double)>& f, double a, double b, double tolerance) {
  if (!(b > a)) return 0.0;
  Simpson s{f};
  // Start from a few panels, so a narrow feature between the first nodes is not missed.
  constexpr int kPanels = 16;
  double total = 0.0;
  for (int i = 0; i < kPanels; ++i) {
    const double lo = a + (b - a) * i / kPanels, hi = a + (b - a) * (i + 1) / kPanels;
    const double flo = s.at(lo), fmid = s.at(0.5 * (lo + hi)), fhi = s.at(hi);
    const double whole = (hi - lo) / 6.0 * (flo + 4.0 * fmid + fhi);
    total += s.refine(lo, hi, flo, fmid, fhi, whole, tolerance / kPanels, 40);
  }
  return s.finite ? total : std::nan("");
}

}  // namespace pdflab::lab
