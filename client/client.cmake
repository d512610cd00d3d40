# The LCM side of the client (`octomap-rt replay`): our generated message types and liblcm.
target_link_libraries(octomap_rt_client PUBLIC octomap_rt_lcmtypes octomap_rt_lcm)
