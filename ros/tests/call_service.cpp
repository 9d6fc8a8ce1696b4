// Calls a std_srvs service of intervox_server the way any ROS 1 client does: with Debian's stock
// std_srvs headers (C++17; see ros/CMakeLists.txt), so the node's own C++20 service types are
// checked against the real ones (a wrong MD5 sum would make the call fail).
//   call_service trigger|empty <service>
// Prints "success=<0|1> message=<text>" and exits with 0 if the call went through, 3 if not.
#include <ros/ros.h>
#include <std_srvs/Empty.h>
#include <std_srvs/Trigger.h>

#include <cstdio>
#include <string>

int main(int argc, char** argv) {
  ros::init(argc, argv, "intervox_call_service", ros::init_options::AnonymousName | ros::init_options::NoRosout);
  if (argc != 3) {
    std::fprintf(stderr, "usage: call_service trigger|empty <service>\n");
    return 2;
  }
  const std::string kind = argv[1], name = argv[2];
  if (!ros::service::waitForService(name, ros::Duration(10.0))) {
    std::printf("success=0 message=service %s not available\n", name.c_str());
    return 3;
  }
  if (kind == "trigger") {
    std_srvs::Trigger srv;
    if (!ros::service::call(name, srv)) return 3;
    std::printf("success=%d message=%s\n", srv.response.success ? 1 : 0, srv.response.message.c_str());
    return 0;
  }
  std_srvs::Empty srv;
  if (!ros::service::call(name, srv)) return 3;
  std::printf("success=1 message=\n");
  return 0;
}
