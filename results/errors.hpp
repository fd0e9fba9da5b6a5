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

/// For a program that exits after a results file failed: HDF5 1.10's own clean-up at exit crashes
/// on a file whose closing failed. Call first in main(), before any HDF5 call; never in a process
/// that shares HDF5 with other code (Python and h5py). rfem's writers close their files themselves.
void disable_hdf5_exit_cleanup();

}  // namespace rfem
