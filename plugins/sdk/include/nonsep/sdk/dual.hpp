#pragma once
// Forward-mode automatic differentiation for plugin models: Dual<S, K> is a number a + sum_k d_k e_k with
// e_j e_k = 0, carrying a value and K first derivatives. Everything lives in fixed-size std::arrays, so
// evaluating a model with duals never allocates.
//
//   Dual<double, K>              value and gradient with respect to K variables (one pass gives grad T).
//   Dual<Dual<double, K>, 1>     a dual of duals: seeding the outer slot with direction e_j gives column j of
//                                the Hessian in the inner derivatives (n passes give the n x n Hessian).
//
// K is the capacity, not necessarily the model's dimension: a model whose dimension is a run-time parameter
// uses K = its max_dimension and seeds only the first n slots; the others stay zero.
//
//   Dual<Dual<Dual<double, K>, 1>, 1>   both outer slots seeded with a direction u: directional third
//                                derivatives sum_ij f_ijk u_i u_j in one pass (automatic_derivatives.hpp).
//
// Supported, for every nesting: + - * / (with duals and with doubles, either side), unary -, compound assignment,
// comparisons of values, and
//   sqrt cbrt exp expm1 log log1p erf abs
//   sin cos tan asin acos atan atan2 sinh cosh tanh asinh acosh atanh hypot
//   pow(x, double)  pow(x, y)  pow(double, y)  min max
// where the two-argument functions (atan2, hypot, pow, min, max) take two duals or a dual and a double.
// Functions with an infinite derivative at a point (sqrt(0), abs(0), acosh(1), ...) give inf or NaN derivatives
// there; outside its domain (log(-1), acosh(0.5), atanh(2)) a function's value and derivatives are NaN: each
// function's derivative rule says so itself, so a derivative never needs the value of the whole function (a
// gradient pass leaves the value unused, and the compiler drops the work only the value needs). Non-finite results
// are numbers, not failures: the SDK's adapter (model_adapter.hpp) returns them as computed and the host reports
// the trajectory as diverged. min and max at a tie take the first argument's derivatives; pow(x, y) has
// derivative 0 in y at x <= 0 (see pow).
//
// Call the functions unqualified, after `using std::sin;` (ADL finds the dual versions, the using-declaration the
// double ones), or as nonsep::sdk::sin etc., which also accept double. std::sin(x) on a dual does not compile
// ("no matching function for call to 'sin(nonsep::sdk::Dual<...>)'"): the standard's functions take only
// arithmetic types, and nothing may be added to namespace std. (A conversion of Dual to double that fails with a
// friendlier static_assert was tried and rejected: it makes `x * 2` ambiguous under clang and `c ? x : 0.0`
// ill-formed.)
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>

// The arithmetic of the dual numbers, and the passes of automatic_derivatives.hpp that drive it, are always inlined:
// left to the compiler, a nested dual's operator*= stayed a call in the model's T and V, and a pass a call from its
// loop (with its seeds and wanted results unknown inside), which made an AD plugin's MEGNO with Gauss-Legendre 1.4x
// slower and its build slower too (bench/autodiff_megno.py). Not forced where nothing is optimised (-O0) or under
// AddressSanitizer: there the forced inlining buys no speed and made clang's builds of the SDK plugins 20-60% slower
// (CI's sanitized build).
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define NONSEP_SDK_SANITIZED_ADDRESSES
#endif
#endif
#if defined(__OPTIMIZE__) && !defined(__SANITIZE_ADDRESS__) && !defined(NONSEP_SDK_SANITIZED_ADDRESSES)
#define NONSEP_SDK_DUAL_INLINE [[gnu::always_inline]] inline
#else
#define NONSEP_SDK_DUAL_INLINE inline
#endif
#undef NONSEP_SDK_SANITIZED_ADDRESSES

namespace nonsep::sdk {

template <class S, std::size_t K>
struct Dual {
  S value{};
  std::array<S, K> derivative{};

  Dual() = default;
  // A constant (all derivatives zero). Implicit so that `S x = 1.0;` works in templated model code.
  Dual(double constant) : value(constant) {}  // NOLINT(google-explicit-constructor)
  Dual(const S& v, const std::array<S, K>& d) : value(v), derivative(d) {}

  // The independent variable number `index` at `at`: derivative e_index.
  static Dual variable(const S& at, std::size_t index) {
    Dual x;
    x.value = at;
    x.derivative[index] = S(1.0);
    return x;
  }

  NONSEP_SDK_DUAL_INLINE Dual& operator+=(const Dual& b) {
    value += b.value;
    for (std::size_t k = 0; k < K; ++k) derivative[k] += b.derivative[k];
    return *this;
  }
  NONSEP_SDK_DUAL_INLINE Dual& operator-=(const Dual& b) {
    value -= b.value;
    for (std::size_t k = 0; k < K; ++k) derivative[k] -= b.derivative[k];
    return *this;
  }
  NONSEP_SDK_DUAL_INLINE Dual& operator*=(const Dual& b) {
    for (std::size_t k = 0; k < K; ++k) derivative[k] = derivative[k] * b.value + value * b.derivative[k];
    value *= b.value;
    return *this;
  }
  NONSEP_SDK_DUAL_INLINE Dual& operator/=(const Dual& b) {
    const S inverse = S(1.0) / b.value;
    value *= inverse;
    for (std::size_t k = 0; k < K; ++k) derivative[k] = (derivative[k] - value * b.derivative[k]) * inverse;
    return *this;
  }
  NONSEP_SDK_DUAL_INLINE Dual& operator+=(double b) {
    value += b;
    return *this;
  }
  NONSEP_SDK_DUAL_INLINE Dual& operator-=(double b) {
    value -= b;
    return *this;
  }
  NONSEP_SDK_DUAL_INLINE Dual& operator*=(double b) {
    value *= b;
    for (auto& d : derivative) d *= b;
    return *this;
  }
  NONSEP_SDK_DUAL_INLINE Dual& operator/=(double b) { return *this *= 1.0 / b; }
};

// The plain double inside any nesting of duals.
inline double value_of(double x) { return x; }
template <class S, std::size_t K>
double value_of(const Dual<S, K>& x) {
  return value_of(x.value);
}

template <class S, std::size_t K>
NONSEP_SDK_DUAL_INLINE Dual<S, K> operator-(Dual<S, K> a) {
  a *= -1.0;
  return a;
}
template <class S, std::size_t K>
NONSEP_SDK_DUAL_INLINE Dual<S, K> operator+(const Dual<S, K>& a) {
  return a;
}

#define NONSEP_SDK_DUAL_BINARY(op)                                                   \
  template <class S, std::size_t K>                                                  \
  NONSEP_SDK_DUAL_INLINE Dual<S, K> operator op(Dual<S, K> a, const Dual<S, K>& b) { \
    a op## = b;                                                                      \
    return a;                                                                        \
  }                                                                                  \
  template <class S, std::size_t K>                                                  \
  NONSEP_SDK_DUAL_INLINE Dual<S, K> operator op(Dual<S, K> a, double b) {            \
    a op## = b;                                                                      \
    return a;                                                                        \
  }
NONSEP_SDK_DUAL_BINARY(+)
NONSEP_SDK_DUAL_BINARY(-)
NONSEP_SDK_DUAL_BINARY(*)
NONSEP_SDK_DUAL_BINARY(/)
#undef NONSEP_SDK_DUAL_BINARY

template <class S, std::size_t K>
NONSEP_SDK_DUAL_INLINE Dual<S, K> operator+(double a, Dual<S, K> b) {
  b += a;
  return b;
}
template <class S, std::size_t K>
NONSEP_SDK_DUAL_INLINE Dual<S, K> operator-(double a, const Dual<S, K>& b) {
  Dual<S, K> r = -b;
  r += a;
  return r;
}
template <class S, std::size_t K>
NONSEP_SDK_DUAL_INLINE Dual<S, K> operator*(double a, Dual<S, K> b) {
  b *= a;
  return b;
}
template <class S, std::size_t K>
NONSEP_SDK_DUAL_INLINE Dual<S, K> operator/(double a, const Dual<S, K>& b) {
  return Dual<S, K>(a) / b;
}

#define NONSEP_SDK_DUAL_COMPARISON(op)                         \
  template <class S, std::size_t K>                            \
  bool operator op(const Dual<S, K>& a, const Dual<S, K>& b) { \
    return value_of(a) op value_of(b);                         \
  }                                                            \
  template <class S, std::size_t K>                            \
  bool operator op(const Dual<S, K>& a, double b) {            \
    return value_of(a) op b;                                   \
  }                                                            \
  template <class S, std::size_t K>                            \
  bool operator op(double a, const Dual<S, K>& b) {            \
    return a op value_of(b);                                   \
  }
NONSEP_SDK_DUAL_COMPARISON(<)
NONSEP_SDK_DUAL_COMPARISON(<=)
NONSEP_SDK_DUAL_COMPARISON(>)
NONSEP_SDK_DUAL_COMPARISON(>=)
NONSEP_SDK_DUAL_COMPARISON(==)
NONSEP_SDK_DUAL_COMPARISON(!=)
#undef NONSEP_SDK_DUAL_COMPARISON

// The double versions, so that nonsep::sdk::sqrt(x) works whatever x is.
using std::abs;
using std::acos;
using std::acosh;
using std::asin;
using std::asinh;
using std::atan;
using std::atan2;
using std::atanh;
using std::cbrt;
using std::cos;
using std::cosh;
using std::erf;
using std::exp;
using std::expm1;
using std::hypot;
using std::log;
using std::log1p;
using std::max;
using std::min;
using std::pow;
using std::sin;
using std::sinh;
using std::sqrt;
using std::tan;
using std::tanh;

// The derivatives whose special cases are rules of their own, written once for the dual numbers below and for the
// gradients nonsep writes for formula models (docs/formula-models.md), for double and duals alike:
//   log_derivative(x)     1/x, NaN below 0 (where log is NaN: 1/x would pretend a derivative exists there)
//   log1p_derivative(x)   1/(1 + x), NaN below -1 (as for log)
//   acosh_derivative(x)   1/sqrt(x^2 - 1), NaN below 1 (acosh is NaN there, though the formula is finite below -1)
//   atanh_derivative(x)   1/(1 - x^2), NaN outside [-1, 1] (atanh is NaN there, the formula finite)
//   abs_derivative(x)     sign(x), NaN at 0 (|x| has no derivative there: a trajectory reaching it diverges)
//   pow_exponent_derivative(x, r)   d/dy x^y = r log x with r = x^y, taken as 0 for x <= 0 (see pow below)
//   min_derivative(a, b, da, db), max_derivative(a, b, da, db)   the derivative of the smaller (larger) argument;
//                         at a tie the first's
template <class S>
S log_derivative(const S& x) {
  return value_of(x) < 0.0 ? S(std::nan("")) : S(S(1.0) / x);
}
template <class S>
S log1p_derivative(const S& x) {
  return value_of(x) < -1.0 ? S(std::nan("")) : S(S(1.0) / (1.0 + x));
}
template <class S>
S acosh_derivative(const S& x) {
  using std::sqrt;
  return value_of(x) < 1.0 ? S(std::nan("")) : S(S(1.0) / sqrt(x * x - 1.0));
}
template <class S>
S atanh_derivative(const S& x) {
  const double v = value_of(x);
  return v < -1.0 || v > 1.0 ? S(std::nan("")) : S(S(1.0) / (1.0 - x * x));
}
template <class S>
S abs_derivative(const S& x) {
  const double v = value_of(x);
  return v == 0.0 ? S(std::nan("")) : S(v > 0.0 ? 1.0 : -1.0);
}
template <class S>
S pow_exponent_derivative(const S& x, const S& r) {
  using std::log;
  return value_of(x) <= 0.0 ? S(0.0) : S(r * log(x));
}
template <class S>
S min_derivative(const S& a, const S& b, const S& da, const S& db) {
  return value_of(b) < value_of(a) ? db : da;
}
template <class S>
S max_derivative(const S& a, const S& b, const S& da, const S& db) {
  return value_of(a) < value_of(b) ? db : da;
}

namespace detail {
// f(x) for a dual x, given f(x.value) and f'(x.value) (both of type S, so nesting works).
template <class S, std::size_t K>
NONSEP_SDK_DUAL_INLINE Dual<S, K> chain(const Dual<S, K>& x, const S& f, const S& f_prime) {
  Dual<S, K> r;
  r.value = f;
  for (std::size_t k = 0; k < K; ++k) r.derivative[k] = f_prime * x.derivative[k];
  return r;
}
// f(x, y) for duals x and y, given f and its partial derivatives f_x and f_y at the values.
template <class S, std::size_t K>
NONSEP_SDK_DUAL_INLINE Dual<S, K> chain(const Dual<S, K>& x, const Dual<S, K>& y, const S& f, const S& f_x,
                                        const S& f_y) {
  Dual<S, K> r;
  r.value = f;
  for (std::size_t k = 0; k < K; ++k) r.derivative[k] = f_x * x.derivative[k] + f_y * y.derivative[k];
  return r;
}
}  // namespace detail

// The two-argument functions with one double argument: the double as a constant dual.
#define NONSEP_SDK_DUAL_MIXED(function)                \
  template <class S, std::size_t K>                    \
  Dual<S, K> function(const Dual<S, K>& x, double y) { \
    return function(x, Dual<S, K>(y));                 \
  }                                                    \
  template <class S, std::size_t K>                    \
  Dual<S, K> function(double x, const Dual<S, K>& y) { \
    return function(Dual<S, K>(x), y);                 \
  }

template <class S, std::size_t K>
Dual<S, K> sqrt(const Dual<S, K>& x) {
  const S r = sqrt(x.value);
  return detail::chain(x, r, S(0.5) / r);
}
template <class S, std::size_t K>
Dual<S, K> cbrt(const Dual<S, K>& x) {
  const S r = cbrt(x.value);
  return detail::chain(x, r, S(1.0) / (3.0 * r * r));
}
template <class S, std::size_t K>
Dual<S, K> exp(const Dual<S, K>& x) {
  const S r = exp(x.value);
  return detail::chain(x, r, r);
}
template <class S, std::size_t K>
Dual<S, K> log(const Dual<S, K>& x) {
  return detail::chain(x, S(log(x.value)), log_derivative(x.value));
}
// x^e for a constant exponent e.
template <class S, std::size_t K>
Dual<S, K> pow(const Dual<S, K>& x, double e) {
  return detail::chain(x, S(pow(x.value, e)), S(e * pow(x.value, e - 1.0)));
}
template <class S, std::size_t K>
Dual<S, K> sin(const Dual<S, K>& x) {
  return detail::chain(x, S(sin(x.value)), S(cos(x.value)));
}
template <class S, std::size_t K>
Dual<S, K> cos(const Dual<S, K>& x) {
  return detail::chain(x, S(cos(x.value)), S(-sin(x.value)));
}
template <class S, std::size_t K>
Dual<S, K> tan(const Dual<S, K>& x) {
  const S r = tan(x.value);
  return detail::chain(x, r, S(1.0 + r * r));
}
template <class S, std::size_t K>
Dual<S, K> asin(const Dual<S, K>& x) {
  return detail::chain(x, S(asin(x.value)), S(S(1.0) / sqrt(1.0 - x.value * x.value)));
}
template <class S, std::size_t K>
Dual<S, K> acos(const Dual<S, K>& x) {
  return detail::chain(x, S(acos(x.value)), S(S(-1.0) / sqrt(1.0 - x.value * x.value)));
}
template <class S, std::size_t K>
Dual<S, K> atan(const Dual<S, K>& x) {
  return detail::chain(x, S(atan(x.value)), S(S(1.0) / (1.0 + x.value * x.value)));
}
template <class S, std::size_t K>
Dual<S, K> sinh(const Dual<S, K>& x) {
  return detail::chain(x, S(sinh(x.value)), S(cosh(x.value)));
}
template <class S, std::size_t K>
Dual<S, K> cosh(const Dual<S, K>& x) {
  return detail::chain(x, S(cosh(x.value)), S(sinh(x.value)));
}
template <class S, std::size_t K>
Dual<S, K> tanh(const Dual<S, K>& x) {
  const S r = tanh(x.value);
  return detail::chain(x, r, S(1.0 - r * r));
}
template <class S, std::size_t K>
Dual<S, K> asinh(const Dual<S, K>& x) {
  return detail::chain(x, S(asinh(x.value)), S(S(1.0) / sqrt(x.value * x.value + 1.0)));
}
template <class S, std::size_t K>
Dual<S, K> acosh(const Dual<S, K>& x) {
  return detail::chain(x, S(acosh(x.value)), acosh_derivative(x.value));
}
template <class S, std::size_t K>
Dual<S, K> atanh(const Dual<S, K>& x) {
  return detail::chain(x, S(atanh(x.value)), atanh_derivative(x.value));
}
template <class S, std::size_t K>
Dual<S, K> expm1(const Dual<S, K>& x) {
  return detail::chain(x, S(expm1(x.value)), S(exp(x.value)));
}
template <class S, std::size_t K>
Dual<S, K> log1p(const Dual<S, K>& x) {
  return detail::chain(x, S(log1p(x.value)), log1p_derivative(x.value));
}
template <class S, std::size_t K>
Dual<S, K> erf(const Dual<S, K>& x) {
  return detail::chain(x, S(erf(x.value)), S(2.0 * std::numbers::inv_sqrtpi * exp(-(x.value * x.value))));
}
// atan2(y, x), the angle of (x, y): d/dy = x / (x^2 + y^2), d/dx = -y / (x^2 + y^2).
template <class S, std::size_t K>
Dual<S, K> atan2(const Dual<S, K>& y, const Dual<S, K>& x) {
  const S inverse = S(1.0) / (x.value * x.value + y.value * y.value);
  return detail::chain(y, x, S(atan2(y.value, x.value)), S(x.value * inverse), S(-y.value * inverse));
}
NONSEP_SDK_DUAL_MIXED(atan2)
template <class S, std::size_t K>
Dual<S, K> hypot(const Dual<S, K>& x, const Dual<S, K>& y) {
  const S r = hypot(x.value, y.value);
  return detail::chain(x, y, r, S(x.value / r), S(y.value / r));
}
NONSEP_SDK_DUAL_MIXED(hypot)
// x^y with both variable: d/dx = y x^(y-1), d/dy = x^y log x, taken as 0 for x <= 0 (the limit at x = 0 for
// y > 0; for x < 0, x^y is real only at integer y and has no derivative in y, and 0 lets pow(x, S(3)) work).
template <class S, std::size_t K>
Dual<S, K> pow(const Dual<S, K>& x, const Dual<S, K>& y) {
  const S r = pow(x.value, y.value);
  return detail::chain(x, y, r, S(y.value * pow(x.value, y.value - 1.0)), pow_exponent_derivative(x.value, r));
}
// a^y for a constant base a.
template <class S, std::size_t K>
Dual<S, K> pow(double a, const Dual<S, K>& y) {
  return pow(Dual<S, K>(a), y);
}
// The smaller (larger) argument with its derivatives; at a tie, the first.
template <class S, std::size_t K>
Dual<S, K> min(const Dual<S, K>& a, const Dual<S, K>& b) {
  return value_of(b) < value_of(a) ? b : a;
}
template <class S, std::size_t K>
Dual<S, K> max(const Dual<S, K>& a, const Dual<S, K>& b) {
  return value_of(a) < value_of(b) ? b : a;
}
NONSEP_SDK_DUAL_MIXED(min)
NONSEP_SDK_DUAL_MIXED(max)
#undef NONSEP_SDK_DUAL_MIXED

// |x| with derivative sign(x). |x| has no derivative at 0: there the derivatives are NaN (a trajectory that reaches
// that point diverges) instead of silently picking a side.
template <class S, std::size_t K>
Dual<S, K> abs(const Dual<S, K>& x) {
  const double v = value_of(x);
  if (v == 0.0) return detail::chain(x, S(0.0), S(std::nan("")));
  return v > 0.0 ? x : -x;
}

// Small helpers for model code, for double and dual alike.
template <class S>
NONSEP_SDK_DUAL_INLINE S square(const S& x) {
  return x * x;
}
template <class S>
NONSEP_SDK_DUAL_INLINE S cube(const S& x) {
  return x * x * x;
}

}  // namespace nonsep::sdk
