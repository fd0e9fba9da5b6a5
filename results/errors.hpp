#pragma once
// The error of the results layer: a results file that cannot be created, written, read or closed
// (a full disk, a file another writer holds, a file that is not rfem's). Its message names the
// file and what failed, in one line.
#include <stdexcept>

namespace rfem {

class ResultsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace rfem
