"""How the node under test is started, and the harness's own ROS node beside it.

Every link that runs a node (over ROS 2, or behind a board's driver) and hunt's
check of a node resolve it here: command, package, launch file or the reference,
its parameters (the user's and the threshold) and the observer's topics."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from harness.errors import OptionError
from harness.links.base import LinkOptions
from harness.nodes.command import NodeCommand, package_node, reference_node, shell_node

if TYPE_CHECKING:
    from harness.launch_files.run_check import LaunchCheck
    from harness.ros.observer import Observer


def node_command(options: LinkOptions) -> NodeCommand:
    """The node the options name: a command, a package in a workspace, or the reference."""
    if options.node and options.package:
        raise OptionError("node", "give either {node} or {package}/{executable}, not both")
    if options.launch:
        if options.node or options.package or options.executable:
            raise OptionError(
                "launch", "{launch} starts the node itself: drop {node}/{package}/{executable}"
            )
        from harness.launch_files.launch_command import launch_node

        return launch_node(*options.launch, options.workspace)
    if options.node:
        return shell_node(options.node)
    if options.package or options.executable:
        if not (options.package and options.executable):
            raise OptionError("package", "{package} and {executable} go together")
        return package_node(options.package, options.executable, options.workspace)
    return reference_node()


def node_parameters(options: LinkOptions) -> tuple[str, ...]:
    """The user's --param items, plus the threshold unless the user set it."""
    params = tuple(options.params)
    name = options.threshold_param
    if name and not any(p.split(":=", 1)[0] == name for p in params):
        params = (f"{name}:={options.threshold!r}", *params)
    return params


def launch_check(options: LinkOptions) -> LaunchCheck | None:
    """The run's launch files (read, not run), when a package or `--launch` names them."""
    by_package = bool(options.package and options.executable and not options.node)
    if not (options.launch or by_package):
        return None
    from harness.launch_files.run_check import LaunchCheck  # the file readers: only for these

    if options.launch:
        package, file = options.launch
        passed = ["use_sim_time", *(p.split(":=", 1)[0] for p in node_parameters(options))]
        return LaunchCheck.for_run(
            package, None, options.workspace, launched=Path(file).name, passed=passed
        )
    return LaunchCheck.for_run(options.package, options.executable, options.workspace)


def harness_observer(options: LinkOptions, domain_id: int, *, publish_scans: bool) -> Observer:
    """The harness's own ROS node in `domain_id`, on the topics and graph the options name."""
    from harness.ros.observer import Observer  # imports rclpy

    return Observer(
        domain_id,
        scan_topic=options.scan_topic,
        status_topic=options.status_topic,
        warning_topic=options.warning_topic,
        network=options.ros_network,
        publish_scans=publish_scans,
    )
