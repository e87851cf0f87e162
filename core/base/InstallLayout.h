// Where cloudbench finds what it reads at run time. Installed (`cmake
// --install`, the .deb), the files lie relative to the executable:
// bin/cloudbench, lib/cloudbench/libcloudbench_images.so,
// share/cloudbench/scenes/ and share/cloudbench/tools/ (the scripts it runs);
// in a build tree, the image module is at the top of the build folder and the
// scenes and scripts in the source tree. The relative paths are
// the install rules' (CMakeLists.txt, harness/CMakeLists.txt), passed in as definitions.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace cb {

// The folder of scene files that a scene name is looked up in: $CLOUDBENCH_SCENES,
// else the installed one when this executable has one, else the source tree's.
std::string SceneFolder();

// The folder of the scripts cloudbench runs (tools/plot_sweep.py): the
// installed one when this executable has one, else the source tree's.
std::string ToolsFolder();

// Where a module cloudbench loads (the image module: harness/report/images)
// may be, in the order to try: beside the executable, the installed place,
// the top of the build tree.
std::vector<std::string> ModuleCandidates(std::string_view fileName);

}  // namespace cb
