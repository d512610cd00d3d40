// Parsing the query commands' arguments: "X,Y,Z" points, "A:B" ranges and boxes, files of
// three numbers a line. Errors throw std::invalid_argument naming the bad text.
#pragma once

#include <string>
#include <vector>

#include "query_client/query_client.h"

namespace ort::client {

std::vector<double> parse_numbers(const std::string& text, size_t count, char sep = ',');  // exactly `count`
std::vector<float> parse_points(const std::vector<std::string>& args);                     // "X,Y,Z" each
std::vector<float> read_points_file(const std::string& path);       // "x y z" (or x,y,z) a line; # comments
Box parse_box(const std::string& text);                             // "X0,Y0,Z0:X1,Y1,Z1"
void parse_range(const std::string& text, double& lo, double& hi);  // "LO:HI"

}  // namespace ort::client
