// Common types, error classes and checks shared by every taut layer.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <sstream>
#include <stdexcept>
#include <string>

namespace taut {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

// Bad user input (mesh file, material, limit, settings). The message says what and where.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A simulation that cannot continue (NaN, explosion). The message names body, element and stage;
// the body keeps its last good state.
class SimulationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace internal {
// Concatenates the arguments with operator<< into one string.
template <typename... Args>
std::string Concat(const Args&... args) {
  std::ostringstream out;
  out.precision(6);
  (out << ... << args);
  return out.str();
}
}  // namespace internal

}  // namespace taut

// Always-on check of user input: throws taut::InputError with the streamed message.
#define TAUT_DEMAND(cond, ...)                                                    \
  do {                                                                            \
    if (!(cond)) throw ::taut::InputError(::taut::internal::Concat(__VA_ARGS__)); \
  } while (0)

// Debug-only invariant check (internal logic, not user input).
#ifndef NDEBUG
#define TAUT_ASSERT(cond)                                                                   \
  do {                                                                                      \
    if (!(cond))                                                                            \
      throw std::logic_error(                                                               \
          ::taut::internal::Concat(__FILE__, ":", __LINE__, ": assertion failed: " #cond)); \
  } while (0)
#else
#define TAUT_ASSERT(cond) \
  do {                    \
  } while (0)
#endif
