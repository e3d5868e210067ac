"""Interop with robot stacks: ROS 2 bags in and out (``bag_*``, ``ingest``) and Spark-DSG / Hydra scene
graphs both ways (``spark_dsg``). The heavy libraries (``rosbags``, ``spark_dsg``) are optional extras,
imported where used (``requirement``)."""
