#pragma once
// Argument checks at the library's public entry points, always on (Pinocchio's
// PINOCCHIO_CHECK_ARGUMENT_SIZE, MFEM's MFEM_VERIFY): a wrong size or index throws
// std::invalid_argument naming the function and the argument instead of reading past a vector.
// They cost a comparison per call; the kernels inside a call do not check again.
#include <stdexcept>
#include <string>

namespace rfem {

/// Throws std::invalid_argument("FUNCTION: WHAT").
[[noreturn]] void throw_argument_error(const char* function, const std::string& what);

}  // namespace rfem

/// Throws std::invalid_argument naming the calling function unless `cond` holds.
#define RFEM_CHECK_ARGUMENT(cond, what)                             \
  do {                                                              \
    if (!(cond)) ::rfem::throw_argument_error(__func__, (what));    \
  } while (0)

/// Throws std::invalid_argument unless `size` equals `expected` ("q has 5 entries, expected 9").
#define RFEM_CHECK_ARGUMENT_SIZE(size, expected, name)                                                     \
  do {                                                                                                     \
    const long rfem_size_ = static_cast<long>(size), rfem_expected_ = static_cast<long>(expected);        \
    if (rfem_size_ != rfem_expected_)                                                                      \
      ::rfem::throw_argument_error(__func__, std::string(name) + " has " + std::to_string(rfem_size_) +   \
                                                 " entries, expected " + std::to_string(rfem_expected_)); \
  } while (0)

/// Throws std::invalid_argument unless 0 ≤ index < size.
#define RFEM_CHECK_INDEX(index, size, name)                                                                 \
  do {                                                                                                      \
    const long rfem_i_ = static_cast<long>(index), rfem_n_ = static_cast<long>(size);                      \
    if (rfem_i_ < 0 || rfem_i_ >= rfem_n_)                                                                  \
      ::rfem::throw_argument_error(__func__, std::string(name) + " = " + std::to_string(rfem_i_) +         \
                                                 " is out of range (0 to " + std::to_string(rfem_n_ - 1) + ")"); \
  } while (0)

namespace rfem {

/// Physical invariants of the model's types (a positive modulus, a non-negative damping): each
/// throws std::invalid_argument("WHAT must be positive (got VALUE)") and the like.
void require_positive(const std::string& what, double value);
void require_non_negative(const std::string& what, double value);
void require_finite(const std::string& what, double value);

}  // namespace rfem
