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
// Supported: + - * / (with duals and with doubles, either side), unary -, compound assignment, comparisons of
// values, and sqrt cbrt exp log pow(x, double) sin cos tan asin acos atan sinh cosh tanh asinh abs. Functions
// with an infinite derivative at a point (sqrt(0), abs(0), ...) give inf or NaN derivatives there; the SDK
// reports a non-finite result as an evaluation failure. Call the functions unqualified (ADL finds them) or as
// nonsep::sdk::sqrt etc., which also accept double.
#include <array>
#include <cmath>
#include <cstddef>

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

  Dual& operator+=(const Dual& b) {
    value += b.value;
    for (std::size_t k = 0; k < K; ++k) derivative[k] += b.derivative[k];
    return *this;
  }
  Dual& operator-=(const Dual& b) {
    value -= b.value;
    for (std::size_t k = 0; k < K; ++k) derivative[k] -= b.derivative[k];
    return *this;
  }
  Dual& operator*=(const Dual& b) {
    for (std::size_t k = 0; k < K; ++k) derivative[k] = derivative[k] * b.value + value * b.derivative[k];
    value *= b.value;
    return *this;
  }
  Dual& operator/=(const Dual& b) {
    const S inverse = S(1.0) / b.value;
    value *= inverse;
    for (std::size_t k = 0; k < K; ++k) derivative[k] = (derivative[k] - value * b.derivative[k]) * inverse;
    return *this;
  }
  Dual& operator+=(double b) {
    value += b;
    return *this;
  }
  Dual& operator-=(double b) {
    value -= b;
    return *this;
  }
  Dual& operator*=(double b) {
    value *= b;
    for (auto& d : derivative) d *= b;
    return *this;
  }
  Dual& operator/=(double b) { return *this *= 1.0 / b; }
};

// The plain double inside any nesting of duals.
inline double value_of(double x) { return x; }
template <class S, std::size_t K>
double value_of(const Dual<S, K>& x) {
  return value_of(x.value);
}

template <class S, std::size_t K>
Dual<S, K> operator-(Dual<S, K> a) {
  a *= -1.0;
  return a;
}
template <class S, std::size_t K>
Dual<S, K> operator+(const Dual<S, K>& a) {
  return a;
}

#define NONSEP_SDK_DUAL_BINARY(op)                                  \
  template <class S, std::size_t K>                                  \
  Dual<S, K> operator op(Dual<S, K> a, const Dual<S, K>& b) {        \
    a op## = b;                                                      \
    return a;                                                        \
  }                                                                  \
  template <class S, std::size_t K>                                  \
  Dual<S, K> operator op(Dual<S, K> a, double b) {                   \
    a op## = b;                                                      \
    return a;                                                        \
  }
NONSEP_SDK_DUAL_BINARY(+)
NONSEP_SDK_DUAL_BINARY(-)
NONSEP_SDK_DUAL_BINARY(*)
NONSEP_SDK_DUAL_BINARY(/)
#undef NONSEP_SDK_DUAL_BINARY

template <class S, std::size_t K>
Dual<S, K> operator+(double a, Dual<S, K> b) {
  b += a;
  return b;
}
template <class S, std::size_t K>
Dual<S, K> operator-(double a, const Dual<S, K>& b) {
  Dual<S, K> r = -b;
  r += a;
  return r;
}
template <class S, std::size_t K>
Dual<S, K> operator*(double a, Dual<S, K> b) {
  b *= a;
  return b;
}
template <class S, std::size_t K>
Dual<S, K> operator/(double a, const Dual<S, K>& b) {
  return Dual<S, K>(a) / b;
}

#define NONSEP_SDK_DUAL_COMPARISON(op)                                                                   \
  template <class S, std::size_t K>                                                                       \
  bool operator op(const Dual<S, K>& a, const Dual<S, K>& b) {                                           \
    return value_of(a) op value_of(b);                                                                    \
  }                                                                                                       \
  template <class S, std::size_t K>                                                                       \
  bool operator op(const Dual<S, K>& a, double b) {                                                      \
    return value_of(a) op b;                                                                              \
  }                                                                                                       \
  template <class S, std::size_t K>                                                                       \
  bool operator op(double a, const Dual<S, K>& b) {                                                      \
    return a op value_of(b);                                                                              \
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
using std::asin;
using std::asinh;
using std::atan;
using std::cbrt;
using std::cos;
using std::cosh;
using std::exp;
using std::log;
using std::pow;
using std::sin;
using std::sinh;
using std::sqrt;
using std::tan;
using std::tanh;

namespace detail {
// f(x) for a dual x, given f(x.value) and f'(x.value) (both of type S, so nesting works).
template <class S, std::size_t K>
Dual<S, K> chain(const Dual<S, K>& x, const S& f, const S& f_prime) {
  Dual<S, K> r;
  r.value = f;
  for (std::size_t k = 0; k < K; ++k) r.derivative[k] = f_prime * x.derivative[k];
  return r;
}
}  // namespace detail

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
  // Below 0 the value is NaN; so is the derivative (1/x would pretend a derivative exists there).
  const S f_prime = value_of(x) < 0.0 ? S(std::nan("")) : S(S(1.0) / x.value);
  return detail::chain(x, S(log(x.value)), f_prime);
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
// |x| with derivative sign(x). |x| has no derivative at 0: there the derivatives are NaN, which the SDK reports
// as an evaluation failure instead of silently picking a side.
template <class S, std::size_t K>
Dual<S, K> abs(const Dual<S, K>& x) {
  const double v = value_of(x);
  if (v == 0.0) return detail::chain(x, S(0.0), S(std::nan("")));
  return v > 0.0 ? x : -x;
}

// Small helpers for model code, for double and dual alike.
template <class S>
S square(const S& x) {
  return x * x;
}
template <class S>
S cube(const S& x) {
  return x * x * x;
}

}  // namespace nonsep::sdk
