#include "logs/pcd_file.hpp"

#include <sstream>

namespace lidarloop {

std::string binary_pcd_header(const std::vector<PcdField>& fields, size_t points, const std::string& comment) {
  std::ostringstream names, sizes, types, counts;
  for (const PcdField& f : fields) {
    names << ' ' << f.name;
    sizes << ' ' << f.size;
    types << ' ' << f.type;
    counts << " 1";
  }
  std::ostringstream head;
  head << "# .PCD v0.7 - " << comment << "\nVERSION 0.7\nFIELDS" << names.str() << "\nSIZE" << sizes.str() << "\nTYPE"
       << types.str() << "\nCOUNT" << counts.str() << "\nWIDTH " << points
       << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << points << "\nDATA binary\n";
  return head.str();
}

}  // namespace lidarloop
