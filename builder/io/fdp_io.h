// FDP files: XfaceEd XML, the plain text form and the visage line form.
// The formats are specified in formats/fdp.md.
#pragma once

#include <string>
#include <string_view>

#include "core/fdp.h"
#include "core/status.h"

namespace afmb {

enum class FdpFormat { Auto, XfaceEd, Text, Visage };

// Reads an FDP file. Auto picks XfaceEd when the text starts with '<' (after
// blanks), else the text form when the first non-comment line is a `fapu`
// line or has 3 or 4 fields, else visage (formats/fdp.md section 5). The
// result is unbound: call bind_fdps() with the scene. Visage mesh indices
// become part names "@N". Errors name the file, line and FDP: an unknown FDP
// name, a malformed number, a missing attribute, a point given twice for the
// same part; an unreadable file names the path and the system's reason.
Expected<FdpSet> read_fdp(const std::string &path, FdpFormat format = FdpFormat::Auto);
Expected<FdpSet> parse_fdp(std::string_view text, const std::string &source_name,
                           FdpFormat format = FdpFormat::Auto);

// Writes the text form: one "FDP part vertex" line per bound point, under the
// scene part's name (an unbound one under its part_name as read), free points
// as "FDP x y z" in round-trip-exact decimals, plus a "fapu" line when `fapu`
// is given. Atomic: on error (a part name with a blank, a non-finite value,
// an I/O failure) nothing is written and the message names `path`.
Status write_fdp_text(const FdpSet &fdps, const Scene &scene, const std::string &path,
                      const Fapu *fapu = nullptr);

}  // namespace afmb
