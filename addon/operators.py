"""The Bake operator: runs addon.jobs.BakeJob in the background, shows its
progress in the status bar, and is cancelled with Esc."""

from __future__ import annotations

import bpy

from . import api, jobs, nodes


class PAINTLUT_OT_bake(bpy.types.Operator):
    """Bake the active material's paint into a lookup table"""

    bl_idname = "paint_lut.bake"
    bl_label = "Bake Paint"
    bl_options = {"REGISTER", "UNDO"}

    force: bpy.props.BoolProperty(name="Force", default=False, description="Bake even if a matching LUT exists")

    _timer = None
    _job = None
    _material = None
    _paint = None
    _type_key = ""

    @classmethod
    def poll(cls, context):
        return getattr(context, "material", None) is not None

    def invoke(self, context, event):
        self._material = context.material
        try:
            paint = api.paint_of(self._material)
        except ValueError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        self._paint = paint
        self._type_key = self._material.paint_lut.type_key()
        self._job = jobs.BakeJob(
            paint, api.lut_directory(), exact_metallic=nodes.EXACT_METALLIC, targets=api.engine_targets(),
            eevee_calibration=api.eevee_calibration(), eevee_mode=api.eevee_mode(context.scene), osl=True,
            force=self.force,
        ).start()  # fmt: skip
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        """Blocking bake, for scripts without an event loop."""
        try:
            result = api.bake_material(context.material, force=self.force)
        except (ValueError, OSError) as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        self._report_fit(context.material)
        self.report({"INFO"}, f"Baked {result.lut_path.name}")
        return {"FINISHED"}

    def _report_fit(self, material):
        for target, fit in api.fit_errors(material).items():
            missed = []
            if fit.error > fit.target:
                missed.append(f"{100 * fit.error:.1f}% misses its {100 * fit.target:.0f}%")
            if fit.grazing > fit.grazing_target:
                missed.append(f"grazing light {100 * fit.grazing:.1f}% misses its {100 * fit.grazing_target:.0f}%")
            if missed:
                self.report({"WARNING"}, f"Paint LUT: {target.title()} fit {', '.join(missed)}")

    def modal(self, context, event):
        if event.type == "ESC":
            self._job.cancel()
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        context.window_manager.progress_update(int(100 * self._job.progress))
        context.workspace.status_text_set(f"Paint LUT: baking {int(100 * self._job.progress)}%  (Esc to cancel)")
        if not self._job.done:
            return {"RUNNING_MODAL"}
        self._finish(context)
        if self._job.error:
            level = {"WARNING"} if self._job.cancelled else {"ERROR"}
            self.report(level, f"Paint LUT: {self._job.error}")
            return {"CANCELLED"}
        api.finish_background_bake(self._material, self._paint, self._job.result, self._type_key)
        self._report_fit(self._material)
        self.report({"INFO"}, f"Baked {self._job.result.lut_path.name}")
        return {"FINISHED"}

    def _finish(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)


CLASSES = (PAINTLUT_OT_bake,)


register, unregister = bpy.utils.register_classes_factory(CLASSES)
