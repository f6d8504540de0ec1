"""The per-fabric sections: the builder of each, running them, and what a fabric's page holds."""

from __future__ import annotations

import dataclasses
import time
from typing import Any, Callable, TypeVar

from reports.report.markup import Markup, html, not_available
from reports.report.page import Page
from reports.report.sec_energy import section_energy
from reports.report.sec_figures import (section_hemisphere, section_lobes, section_masking,
                                        section_slices)
from reports.report.sec_fit import section_fit
from reports.report.sec_parameters import section_parameters
from reports.report.sec_reciprocity import section_reciprocity
from reports.report.sec_renders import section_renders
from reports.report.sec_sanity import section_sanity
from reports.report.settings import SECTIONS, TITLES, Section, Unavailable

__all__ = ["BUILDERS", "SectionRun", "FabricReport", "run_section"]

#: Section name -> builder: a function of a :class:`Page` returning a :class:`Section`.
BUILDERS: dict[str, Callable[[Page], Section]] = {
    "parameters": section_parameters, "lobes": section_lobes, "slices": section_slices,
    "hemisphere": section_hemisphere, "masking": section_masking, "energy": section_energy,
    "reciprocity": section_reciprocity, "sanity": section_sanity, "renders": section_renders,
    "fit": section_fit,
}
assert tuple(BUILDERS) == SECTIONS

T = TypeVar("T")


@dataclasses.dataclass(frozen=True)
class SectionRun:
    """One section of one fabric as built: its name, "ok" or why not, seconds, output."""

    name: str
    status: str
    seconds: float
    section: Section

    def html(self, fabric_name: str) -> Markup:
        """The section's ``<section>`` element on the fabric's page."""
        return html('<section id="{}" class="report-section" data-fabric="{}"><h2>{}</h2>'
                    "{}</section>", self.name, fabric_name, TITLES[self.name],
                    self.section.html)


@dataclasses.dataclass
class FabricReport:
    """Everything built for one fabric: its sections in page order."""

    name: str
    fabric: Any
    runs: list[SectionRun] = dataclasses.field(default_factory=list)

    def data(self, cls: type[T]) -> T | None:
        """The data of the section that produced a ``cls``, or None when none did."""
        for r in self.runs:
            if isinstance(r.section.data, cls):
                return r.section.data
        return None

    def summary(self) -> dict[str, Any]:
        """The fabric's entry of ``summary.json``: each section's status and seconds, then
        what each section's data adds, in page order."""
        out: dict[str, Any] = {"sections": {r.name: {"status": r.status, "seconds": r.seconds}
                                            for r in self.runs}}
        for r in self.runs:
            if r.section.data is not None:
                out.update(r.section.data.summary())
        return out


def run_section(name: str, page: Page) -> SectionRun:
    """Build section ``name`` on ``page``; :class:`Unavailable` becomes a "not available" run."""
    t0 = time.perf_counter()
    try:
        sec = BUILDERS[name](page)
        status = "ok"
    except Unavailable as exc:
        sec = Section(not_available(str(exc)))
        status = f"not available: {exc}"
    return SectionRun(name, status, round(time.perf_counter() - t0, 3), sec)
