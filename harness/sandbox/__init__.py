"""Students' builds and nodes in a bubblewrap sandbox (``grade``'s default).

- ``bwrap``: the bwrap command line for a view of the machine (pure).
- ``views``: what a student's build, judging run and node each see.
- ``probe``: is bubblewrap here and allowed to make a sandbox; the fix if not.
- ``student``: one student's three sandboxes, as the grader starts them
  (the node's prefix goes to ``harness.nodes.sandbox_prefix``).
- ``refusals``: a failure the sandbox caused, told as such (pure).
"""
