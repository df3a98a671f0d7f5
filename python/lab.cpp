// pdflab.lab: the 1D lab (renderer/lab), the book's first chapters.
#include "python/bindings.h"

#include "renderer/error.h"
#include "renderer/lab/expression.h"
#include "renderer/lab/lab1d.h"
#include "renderer/sampling/rng.h"

#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <cmath>
#include <functional>

namespace pdflab::python {

namespace {

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;

// Short names for the built-in integrands and pdfs (their long names, as the
// viewer shows them, come with lab.integrands() and lab.pdfs()).
constexpr const char* kIntegrandKeys[] = {"square", "cosine", "step", "narrow-peak"};
constexpr const char* kPdfKeys[] = {"uniform", "linear", "quadratic", "mismatched"};

std::string keys(const char* const* list, int n) {
  std::string s;
  for (int i = 0; i < n; ++i) s += (i ? ", " : "") + std::string(list[i]);
  return s;
}

lab::Pdf pdf_of(const std::string& key) {
  for (int i = 0; i < static_cast<int>(lab::Pdf::Count); ++i)
    if (key == kPdfKeys[i]) return static_cast<lab::Pdf>(i);
  throw InputError("unknown pdf '" + key + "' (" + keys(kPdfKeys, static_cast<int>(lab::Pdf::Count)) + ")");
}

std::optional<lab::Integrand> builtin(const py::object& f) {
  if (!py::isinstance<py::str>(f)) return std::nullopt;
  const std::string key = f.cast<std::string>();
  for (int i = 0; i < static_cast<int>(lab::Integrand::Count); ++i)
    if (key == kIntegrandKeys[i]) return static_cast<lab::Integrand>(i);
  return std::nullopt;
}

// An integrand: a built-in's name, an expression ("sin(pi*x)^2", as typed in
// the viewer's lab) or a Python function of one float.
std::function<double(double)> integrand_of(const py::object& f) {
  if (const auto b = builtin(f)) return [b](double x) { return lab::integrand(*b, x); };
  if (py::isinstance<py::str>(f)) return lab::Expression::parse(f.cast<std::string>()).function();
  if (PyCallable_Check(f.ptr())) {
    return [f](double x) { return f(x).cast<double>(); };
  }
  throw InputError("an integrand is a built-in's name (" +
                   keys(kIntegrandKeys, static_cast<int>(lab::Integrand::Count)) +
                   "), an expression in x such as 'sin(pi*x)^2', or a function");
}

template <class F>
py::array_t<double> each(const Doubles& x, F&& f) {
  std::vector<py::ssize_t> shape(x.shape(), x.shape() + x.ndim());
  py::array_t<double> out(shape);
  const double* in = x.data();
  double* o = out.mutable_data();
  for (py::ssize_t i = 0; i < x.size(); ++i) o[i] = f(in[i]);
  return out;
}

}  // namespace

void bind_lab(py::module_& m) {
  m.doc() = R"(The 1D lab: integrate f over [0, 2] by Monte Carlo, sampling x from a pdf by its inverse CDF.

Integrands: a built-in's name (lab.integrands()), an expression in x as the
viewer's lab takes it ('sin(pi*x)^2', muParser's syntax), or a function.
Pdfs: lab.pdfs().)";
  m.attr("low") = lab::kLow;
  m.attr("high") = lab::kHigh;

  m.def("integrands", [] {
    py::list rows;
    for (int i = 0; i < static_cast<int>(lab::Integrand::Count); ++i) {
      const auto f = static_cast<lab::Integrand>(i);
      py::dict row;
      row["key"] = kIntegrandKeys[i];
      row["name"] = std::string(lab::integrand_name(f));
      row["exact"] = lab::exact_integral(f);
      rows.append(row);
    }
    return rows;
  });
  m.def("pdfs", [] {
    py::list rows;
    for (int i = 0; i < static_cast<int>(lab::Pdf::Count); ++i) {
      py::dict row;
      row["key"] = kPdfKeys[i];
      row["name"] = std::string(lab::pdf_name(static_cast<lab::Pdf>(i)));
      rows.append(row);
    }
    return rows;
  });

  m.def(
      "f", [](const py::object& integrand, const Doubles& x) { return each(x, integrand_of(integrand)); },
      py::arg("integrand"), py::arg("x"), "The integrand at x (an array).");
  m.def(
      "pdf", [](const std::string& p, const Doubles& x) { return each(x, [q = pdf_of(p)](double v) { return lab::pdf(q, v); }); },
      py::arg("pdf"), py::arg("x"));
  m.def(
      "cdf", [](const std::string& p, const Doubles& x) { return each(x, [q = pdf_of(p)](double v) { return lab::cdf(q, v); }); },
      py::arg("pdf"), py::arg("x"));
  m.def(
      "inverse_cdf",
      [](const std::string& p, const Doubles& u) {
        const lab::Pdf q = pdf_of(p);
        return each(u, [q](double v) {
          if (!(v >= 0.0 && v < 1.0)) throw InputError("inverse_cdf: u must lie in [0, 1), not " + std::to_string(v));
          return lab::inverse_cdf(q, v);
        });
      },
      py::arg("pdf"), py::arg("u"), "The sample x for u in [0, 1): how the lab draws from the pdf.");
  m.def(
      "exact_integral",
      [](const py::object& integrand) {
        if (const auto b = builtin(integrand)) return lab::exact_integral(*b);
        const std::function<double(double)> f = integrand_of(integrand);
        const double v = lab::integrate(f, lab::kLow, lab::kHigh);
        if (!std::isfinite(v)) throw InputError("the integrand is not finite everywhere on [0, 2]");
        return v;
      },
      py::arg("integrand"),
      "The integral over [0, 2]: exact for a built-in, by adaptive quadrature otherwise (as the viewer's lab).");
  m.def(
      "has_finite_variance",
      [](const std::string& integrand, const std::string& p) {
        const auto b = builtin(py::str(integrand));
        if (!b)
          throw InputError("has_finite_variance knows the built-in integrands only (" +
                           keys(kIntegrandKeys, static_cast<int>(lab::Integrand::Count)) + ")");
        return lab::has_finite_variance(*b, pdf_of(p));
      },
      py::arg("integrand"), py::arg("pdf"),
      "Whether f(x)/p(x) has a finite variance (where p falls to 0 faster than f, it does not).");
  m.def(
      "estimate",
      [](const py::object& integrand, const std::string& p, std::int64_t n, std::uint64_t seed,
         const std::optional<Doubles>& u) {
        lab::Estimator estimator(integrand_of(integrand), pdf_of(p));
        std::vector<double> us;
        if (u) {
          us.assign(u->data(), u->data() + u->size());
        } else {
          if (n < 1 || n > 100000000) throw InputError("n must be in 1..100000000");
          Rng rng(seed, 0);
          us.resize(static_cast<std::size_t>(n));
          for (double& v : us) v = rng.uniform();
        }
        const auto count = static_cast<py::ssize_t>(us.size());
        py::array_t<double> x(count), values(count), running(count), error(count);
        const lab::Pdf q = pdf_of(p);
        for (py::ssize_t i = 0; i < count; ++i) {
          const double ui = us[static_cast<std::size_t>(i)];
          if (!(ui >= 0.0 && ui < 1.0)) throw InputError("u[" + std::to_string(i) + "] is not in [0, 1)");
          x.mutable_data()[i] = lab::inverse_cdf(q, ui);
          values.mutable_data()[i] = estimator.add(ui);
          running.mutable_data()[i] = estimator.mean();
          error.mutable_data()[i] = estimator.standard_error();
        }
        py::dict d;
        d["estimate"] = estimator.mean();
        d["standard_error"] = estimator.standard_error();
        d["variance"] = estimator.variance();
        d["n"] = estimator.count();
        d["x"] = x;
        d["values"] = values;
        d["running_estimate"] = running;
        d["running_standard_error"] = error;
        return d;
      },
      py::arg("integrand"), py::arg("pdf"), py::arg("n") = 1000, py::arg("seed") = 1, py::arg("u") = py::none(),
      R"(The Monte Carlo estimate of the integral of f over [0, 2] with x drawn from the pdf.

From `u` (numbers in [0, 1)) or n numbers of pdflab's generator with `seed`.
Returns estimate, standard_error, variance (of one sample f(x)/p(x)), n, and
per sample x, f(x)/p(x) (values), the running estimate and its standard error.)");
  m.def(
      "estimate_pi",
      [](std::uint64_t n, std::uint64_t seed, bool stratified) {
        return stratified ? lab::estimate_pi_stratified(n, seed) : lab::estimate_pi(n, seed);
      },
      py::arg("n"), py::arg("seed") = 1, py::arg("stratified") = false,
      "pi from n points in the unit square (stratified: one jittered point per cell of a sqrt(n) grid).");
}

}  // namespace pdflab::python
