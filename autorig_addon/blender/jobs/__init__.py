"""The add-on's jobs, without operator UI: what the operators and the
command line run (as Blender's glTF add-on's operator calls
``blender.exp.export.save``).

One module per job: ``transfer``, ``skin``, ``rig`` (skeleton prediction,
Auto-Rig and the live re-clustering), ``rignet`` (RigNet rig files); each
holds the job's settings and its plan / compute / write functions, so
nothing is written before everything is computed. ``worker_job`` is the
``bpy``-free computation a modal operator runs in a thread;
``input_checks`` what skin and transfer check alike.
"""
