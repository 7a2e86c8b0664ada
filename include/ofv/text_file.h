/**
 * \file
 * \brief Reading a whole input file (scenario, grid, scene, list) safely.
 */
#pragma once

#include <cstdint>
#include <string>

namespace ofv {

/**
 * \brief The contents of the regular file at `path`, at most `max_bytes` long.
 *
 * The limit is checked while reading, so a file that keeps growing stops
 * there; anything but a regular file (a directory, a device such as
 * /dev/zero, a FIFO, a socket) is refused before it is opened, so that
 * nothing blocks on a FIFO without a writer.
 * \param path      the file.
 * \param max_bytes the longest file accepted [bytes].
 * \param what      what the file was expected to be ("scenario", "grid", ...), for the messages.
 * \throws std::invalid_argument naming the path and `what`: missing, not a
 *         regular file, unreadable, or longer than `max_bytes`.
 */
[[nodiscard]] std::string read_text_file(const std::string& path, std::uintmax_t max_bytes, const std::string& what);

}  // namespace ofv
