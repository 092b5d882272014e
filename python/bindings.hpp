// The parts of the Python module crowddb._core, one translation unit each (pybind11 code is slow
// to compile): the simulation (module.cpp), the queries on arrays (queries.cpp), the SDF
// functions and the error classes (sdf_module.cpp).
#pragma once

#include <pybind11/pybind11.h>

namespace crowddb::python {

// crowddb.Error and its subclasses InputError (also a ValueError), InvalidRow (an InputError with
// .field), IOError_ (also an OSError), UsageError; crowddb::Error and sdf::Error become them with
// the same one-line messages.
void register_errors(pybind11::module_& m);
void bind_queries(pybind11::module_& m);
void bind_sdf(pybind11::module_& m);

}  // namespace crowddb::python
