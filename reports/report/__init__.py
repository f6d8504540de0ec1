"""The HTML report: every preset's parameters, lobes, slices, masking, energy, reciprocity,
sanity scan and renders, and an overview page comparing them.

Layout of the output folder::

    index.html            overview: parameter table, combined lobes, albedo comparison
    NAME.html             one page per fabric, one <section> per report section
    NAME/*.png            its figures;  NAME/*.json, NAME/*.csv  its data
    overview/*.png|csv    the overview's figures and data
    summary.json          everything the pages say, as data
    .microcyl-report      marker: this folder is a report that a later run may replace

Each section is a module ``sec_<topic>.py`` whose builder takes a :class:`~reports.report.page.Page`
and returns a :class:`Section`: its HTML and its data (a small dataclass whose ``summary()``
is the section's part of ``summary.json``). The overview reads the sections' data objects.
A section that cannot be shown for a fabric (no fit results, no masking to switch off)
raises :class:`Unavailable` and says "Not available" and why; it never stops the report.

Nothing is written half: the report is built in a hidden temporary folder beside the output
folder (every file in it written through a temporary file and ``os.replace``) and renamed into
place at the end; an interrupted or failed run removes the temporary folder.
"""

from reports.report.build import build_report
from reports.report.folder import check_output_dir
from reports.report.sections import BUILDERS, FabricReport
from reports.report.settings import QUALITIES, SECTIONS, Section, Unavailable

__all__ = ["build_report", "SECTIONS", "QUALITIES", "Unavailable", "check_output_dir",
           "Section", "BUILDERS", "FabricReport"]
