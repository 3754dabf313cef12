// digest.hpp — SHA-256 and random job ids (OpenSSL's libcrypto).
//
// Result files are recorded with their SHA-256 so clients can verify a
// download; request bodies are hashed for the Idempotency-Key check. Job ids
// are UUID version 4 from the operating system's CSPRNG, so they cannot be
// guessed from one another.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace hmpm::server {

/// Lowercase hex SHA-256 of `bytes`.
std::string sha256_hex(std::string_view bytes);

/// Lowercase hex SHA-256 of a file's content; nullopt if it cannot be read.
std::optional<std::string> sha256_file_hex(const std::filesystem::path& path);

/// A random RFC 4122 version 4 UUID, lowercase ("xxxxxxxx-xxxx-4xxx-yxxx-xxxxxxxxxxxx").
std::string new_uuid_v4();

/// True for exactly the shape new_uuid_v4 produces (lowercase hex, dashes at 8-4-4-4-12).
bool looks_like_uuid(std::string_view text);

}  // namespace hmpm::server
