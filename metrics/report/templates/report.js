function drawCharts(root){root.querySelectorAll('script[data-chart]').forEach(function(s){
  var id=s.getAttribute('data-chart');var el=document.getElementById(id);
  if(el.dataset.drawn)return;var fig=JSON.parse(s.textContent);el.dataset.drawn='1';
  Plotly.newPlot(el,fig.data,fig.layout,{responsive:true,displaylogo:false});});}
function showBuilding(name){
  document.querySelectorAll('section.building').forEach(function(s){
    s.hidden=s.dataset.scene!==name;});
  document.querySelectorAll('nav.buildings button').forEach(function(b){
    b.classList.toggle('active',b.dataset.scene===name);});
  var sec=document.querySelector('section.building[data-scene="'+name+'"]');
  if(sec)drawCharts(sec);}
function sortTable(th){var table=th.closest('table');var body=table.tBodies[0];
  var col=Array.prototype.indexOf.call(th.parentNode.children,th);
  var asc=th.dataset.order!=='asc';th.dataset.order=asc?'asc':'desc';
  var rows=Array.prototype.slice.call(body.rows);
  rows.sort(function(a,b){var x=a.cells[col].dataset.sort,y=b.cells[col].dataset.sort;
    var nx=parseFloat(x),ny=parseFloat(y);
    var c=(isNaN(nx)||isNaN(ny))?String(x).localeCompare(String(y)):nx-ny;
    return asc?c:-c;});
  rows.forEach(function(r){body.appendChild(r);});}
function filterFamily(sel){var t=document.getElementById(sel.dataset.table);
  Array.prototype.forEach.call(t.tBodies[0].rows,function(r){
    r.hidden=sel.value!=='*'&&r.dataset.family!==sel.value;});}
document.addEventListener('DOMContentLoaded',function(){
  document.querySelectorAll('table.sortable th').forEach(function(th){
    th.addEventListener('click',function(){sortTable(th);});});
  document.querySelectorAll('nav.buildings button').forEach(function(b){
    b.addEventListener('click',function(){showBuilding(b.dataset.scene);});});
  document.querySelectorAll('select.family').forEach(function(s){
    s.addEventListener('change',function(){filterFamily(s);});});
  drawCharts(document.getElementById('overview'));});
