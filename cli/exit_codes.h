// The frep command's exit codes and error type: the io library's (frep/io/error.h), which the
// readers and writers throw. Commands see the io library's names unqualified.
#pragma once

#include "frep/io/error.h"

namespace frep::cli {

using namespace frep::io;
using CliError = io::Error;

}  // namespace frep::cli
